// One translucent fragment blended into the moment shadow map with the over operator (JCGT §3):
// moments' = alpha b(z) + (1 - alpha) moments, back to front (the draws and their triangles are
// sorted). alpha is the material's opacity times the fraction of the texel's opaque depth samples
// behind the fragment (a translucent surface behind an opaque one casts nothing there); below the
// threshold (1% by default, frame.shading.z) the fragment is discarded: many nearly transparent
// fragments would otherwise accumulate the rounding of every blend.
// The fragment's depth is in the convention of the opaque depth pass for its layer: the
// orthographic depth of a directional light, the radial distance / range of a spot light or a
// point light's face (shadow_depth_spot.frag), taken at the texel's centre like the
// orthographic one and compared, like it, with each opaque sample's depth.
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_TRANSLUCENT_LIGHTS
#include "msm/techniques.h"
#include "msm/local_light.h"
#include "frame.glsl"
#include "local_light_depth.glsl"

layout(binding = MSM_BINDING_TRANSLUCENT_OPACITY) uniform sampler2D opacity_texture;
#define MSM_DEPTH_BINDING MSM_BINDING_TRANSLUCENT_DEPTH
#include "depth_map.glsl"
layout(push_constant) uniform Push { ObjectPush object; };

layout(location = 0) in vec2 texcoord;
layout(location = 1) in vec3 world_position;
layout(location = 0) out vec4 out0;
#ifdef MSM_TWO_TARGETS
layout(location = 1) out vec4 out1;
#endif

void main() {
  float alpha = object.albedo_opacity.a;
  if (object.flags.z != 0) alpha *= texture(opacity_texture, texcoord).x;
  // Coloured translucency: this pass blends one colour channel's map, with that channel's opacity.
  if (object.flags.w >= 0) alpha *= 1.0f - object.transmission[object.flags.w];
  ivec2 p = ivec2(gl_FragCoord.xy);
  LightUniforms light = lights[object.light.x];
  bool local_light = light.spot_position.w > 0.0f;
  float z = local_light ? local_light_map_depth(light, world_position) : gl_FragCoord.z;
  int samples = frame.kernel.y, behind = 0;
  for (int s = 0; s < samples; ++s) behind += depth_sample(p, s) > z ? 1 : 0;
  alpha *= float(behind) / float(samples);
  if (alpha < frame.shading.z || alpha <= 0.0f) discard;
  vec4 m = msm_technique_generate(kTechnique, z, frame.technique_params).a;
  out0 = vec4(m.x, m.y, m.z, alpha);
#ifdef MSM_TWO_TARGETS
  out0 = vec4(m.x, m.y, 0.0f, alpha);
  out1 = vec4(m.z, m.w, 0.0f, alpha);
#endif
}
