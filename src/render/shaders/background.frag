// The background of a probe-lit scene: the probe's radiance in the pixel's view direction (its
// nearest texel, msm_cube_texel, as the ray tracer shows it), tone mapped like the surfaces, or
// linear for the scattering techniques (their pass composites and tone maps it).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/light_probe.h"
#include "frame.glsl"

layout(constant_id = MSM_SPEC_LINEAR_RADIANCE) const bool kLinearRadiance = false;

layout(binding = MSM_BINDING_BACKGROUND_PROBE) uniform sampler2DArray probe; // six faces of linear RGB radiance
layout(push_constant) uniform Push { ScatteringPush scatter; };

layout(location = 0) out vec4 out_color;

void main() {
  vec2 ndc = gl_FragCoord.xy / frame.camera_viewport.xy * 2.0f - 1.0f;
  vec4 far = scatter.inverse_view_projection * vec4(ndc, 1.0f, 1.0f);
  vec3 direction = far.xyz / far.w - scatter.camera.xyz;
  vec3 radiance = texelFetch(probe, msm_cube_texel(direction, textureSize(probe, 0).x), 0).rgb;
  out_color = kLinearRadiance ? vec4(radiance, 1.0f) : vec4(msm_aces(radiance * frame.shading.y), 1.0f);
}
