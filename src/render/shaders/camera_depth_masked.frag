// The camera's depth pre-pass of alpha-tested objects: the cut-outs write no depth, as the shading
// shows no surface there.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#include "msm/render/frame.h"
#include "alpha_test.glsl"

layout(binding = MSM_BINDING_CAMERA_DEPTH_OPACITY) uniform sampler2D opacity_texture;
layout(push_constant) uniform Push {
  ObjectPush object;
  mat4 view_projection;
};

layout(location = 0) in vec2 texcoord;

void main() {
  if (!alpha_test_passes(object, true, opacity_texture, texcoord)) discard;
}
