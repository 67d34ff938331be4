// Shadow depth pass of alpha-tested occluders: fragments of the cut-outs write no depth.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "alpha_test.glsl"

layout(binding = MSM_BINDING_SHADOW_DEPTH_MASKED_OPACITY) uniform sampler2D opacity_texture;
layout(push_constant) uniform Push { ObjectPush object; };

layout(location = 0) in vec2 texcoord;

void main() {
  if (!alpha_test_passes(object, true, opacity_texture, texcoord)) discard;
}
