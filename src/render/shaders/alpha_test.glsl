// Alpha testing (glTF alphaMode MASK), shared by the shadow depth pass and the shading: an
// alpha-tested surface exists where its opacity, the constant times the opacity texture, reaches
// the cutoff (object.transmission.w; 0: not alpha-tested, every fragment passes). The ray tracer
// tests the same opacity (msm::reference Tracer::solid). textures: false where no draw of the frame
// has one (a constant: see kTexturedDraws in shading.glsl).
bool alpha_test_passes(ObjectPush object, bool textures, sampler2D opacity_texture, vec2 texcoord) {
  float alpha = object.albedo_opacity.a;
  if (textures && object.flags.z != 0) alpha *= texture(opacity_texture, texcoord).x;
  return alpha >= object.transmission.w;
}
