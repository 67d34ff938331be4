// Shadow-map lookups of the filtered techniques (MSM_LOOKUP_*): where to read, and the
// bilinear weights. The blue-noise textures (64 layers, RG8) dither the nearest lookup.
layout(binding = 4) uniform sampler2DArray blue_noise;

// Texel-centre coordinate t (texel i covers [i - 0.5, i + 0.5)) -> the texel a nearest or
// dithered lookup reads, clamped to the map.
ivec2 lookup_texel(vec2 t) {
  if (frame.lookup.x == MSM_LOOKUP_DITHER) {
    ivec2 n = (ivec2(gl_FragCoord.xy) + frame.lookup.zw) & 63;
    t += texelFetch(blue_noise, ivec3(n, frame.lookup.y), 0).xy - 0.5f;
  }
  int last = int(frame.shadow_map.x) - 1;
  return clamp(ivec2(floor(t + 0.5f)), ivec2(0), ivec2(last));
}

// The receiver plane's depth at the centre of texel i: a nearest or dithered lookup reads a
// texel up to a texel away from the fragment, and comparing with the fragment's own depth there
// would shadow sloped receivers by their own slope (acne).
float receiver_depth_at(ShadowLookup s, ivec2 i) { return s.z + dot(s.depth_per_texel, vec2(i) - s.t); }

// The four texels of a bilinear lookup at t (clamped) and their weights (x: i0, y: i0 + 1).
struct Bilinear {
  ivec2 i0, i1;
  vec2 f;
};
Bilinear bilinear_texels(vec2 t) {
  int last = int(frame.shadow_map.x) - 1;
  vec2 base = floor(t);
  Bilinear b;
  b.f = t - base;
  b.i0 = clamp(ivec2(base), ivec2(0), ivec2(last));
  b.i1 = clamp(ivec2(base) + 1, ivec2(0), ivec2(last));
  return b;
}
