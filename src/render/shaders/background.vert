// One triangle covering the viewport at the far plane (depth 1): drawn where no surface is (depth
// test LESS_OR_EQUAL against the cleared depth 1), the background of a probe-lit scene.
#version 460

void main() {
  vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
  gl_Position = vec4(p * 2.0f - 1.0f, 1.0f, 1.0f);
}
