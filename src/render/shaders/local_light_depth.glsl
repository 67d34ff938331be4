// The depth a spot light's or a point light's face's map stores for a caster at `position`: the
// radial distance over the range (msm_local_light_depth, docs/techniques.md "Light kinds"), clamped
// to [0, 1] (casters beyond the range store 1). The opaque depth pass writes it, the translucent
// pass blends it. The including file has msm/local_light.h and frame.glsl (LightUniforms).
float local_light_map_depth(LightUniforms light, vec3 position) {
  return clamp(msm_local_light_depth(distance(position, light.spot_position.xyz), light.spot_position.w), 0.0f, 1.0f);
}
