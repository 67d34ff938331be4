// Moment soft shadows (msm-mssm4) for a directional light, from msm's shared headers
// (src/glsl/msm_three_soft.h; no formula is written here): its depth map becomes a 32-bit integer
// summed-area table in WebGL 2, as the renderer's `mssm4` builds it with compute shaders.
//  - texels: each depth texel's Θ4* moments, quantized for the renderer's kernel of 27 x 27 texels
//    (msm_three_sat_texel), into an RGBA32UI render target (integer formats are colour-renderable
//    in WebGL 2 core);
//  - prefix sums by recursive doubling (Hillis and Steele): pass k adds the texel 2^k to the left
//    (then below), log2(width) passes along x and log2(height) along y, ping-ponging two RGBA32UI
//    targets. WebGL 2's highp uint arithmetic wraps modulo 2^32, as sat.h's tables rely on: the
//    rectangle sums are exact however often the running sums wrapped;
//  - the light's values (tan of half its angular diameter, world units per unit of [-1,1] depth
//    and per texel) in a 1 x 1 float texture, which the package binds where three.js binds the
//    light's shadow map: the lookup (index.js's getShadow) recognizes the soft light by it and
//    reads the table from a uniform of its own (WebGL 2 binds no integer texture to three.js's
//    float shadow samplers).
// One directional light per renderer has soft shadows (the table is one uniform).
import { WebGLRenderTarget, RawShaderMaterial, GLSL3, UnsignedIntType, RGBAIntegerFormat, FloatType, RGBAFormat,
  NearestFilter, ClampToEdgeWrapping, DataTexture, Vector2, Vector4 } from 'three';
import { MSM_THREE_GLSL, MSM_THREE_SOFT_GLSL } from './generated/msm-glsl.js';

// The light's angular diameter in degrees (the renderer's --light-extent-deg, a disc).
export const DEFAULT_SOFT = Object.freeze({ angularDiameter: 2 });

const VERTEX = `
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}`;

// Each depth texel's entry of the table.
const TEXELS = `${MSM_THREE_GLSL}${MSM_THREE_SOFT_GLSL}
uvec4 msm_three_sat_fetch(int x, int y, int table) { return uvec4(0u); } // no lookup here
uniform highp sampler2D depthMap;
layout(location = 0) out highp uvec4 texel;
void main() { texel = msm_three_sat_texel(texelFetch(depthMap, ivec2(gl_FragCoord.xy), 0).x, MSM_THREE_SOFT_KERNEL); }`;

// One step of the prefix sums: the running sum plus the one `offset` texels before it (uint, wrapping).
const PREFIX_STEP = `
precision highp float;
precision highp int;
precision highp usampler2D;
uniform usampler2D source;
uniform ivec2 offset;
layout(location = 0) out uvec4 sum;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), q = p - offset;
  sum = texelFetch(source, p, 0);
  if (q.x >= 0 && q.y >= 0) sum += texelFetch(source, q, 0);
}`;

// The light's values, as the lookup reads them.
const LIGHT = `
precision highp float;
uniform vec4 light;
layout(location = 0) out vec4 values;
void main() { values = light; }`;

function pass(fragmentShader, uniforms) {
  return new RawShaderMaterial({ glslVersion: GLSL3, vertexShader: VERTEX, fragmentShader, uniforms, depthTest: false, depthWrite: false });
}

function target(width, height, integer) {
  const t = new WebGLRenderTarget(width, height, {
    type: integer ? UnsignedIntType : FloatType, format: integer ? RGBAIntegerFormat : RGBAFormat,
    minFilter: NearestFilter, magFilter: NearestFilter, wrapS: ClampToEdgeWrapping, wrapT: ClampToEdgeWrapping,
    depthBuffer: false, generateMipmaps: false,
  });
  if (integer) t.texture.internalFormat = 'RGBA32UI';
  t.texture.name = 'msm-three soft';
  return t;
}

export class SoftShadowTables {
  // draw(material, target): the package's full-screen pass.
  constructor(draw) {
    this._draw = draw;
    this._texels = pass(TEXELS, { depthMap: { value: null } });
    this._step = pass(PREFIX_STEP, { source: { value: null }, offset: { value: new Vector2() } });
    this._light = pass(LIGHT, { light: { value: new Vector4() } });
    // Bound in the materials before any table exists: an integer texture of one zero texel.
    this._empty = new DataTexture(new Uint32Array(4), 1, 1, RGBAIntegerFormat, UnsignedIntType);
    this._empty.internalFormat = 'RGBA32UI';
    this._empty.needsUpdate = true;
    this.table = { value: this._empty }; // the materials' msmThreeSatTable
  }

  // A light's state: two tables to ping-pong and its 1 x 1 light texture (the light's shadow.map).
  state(width, height, previous) {
    if (previous && previous.tables[0].width === width && previous.tables[0].height === height) return previous;
    previous && this.release(previous);
    return { tables: [target(width, height, true), target(width, height, true)], light: target(1, 1, false) };
  }

  release(state) {
    for (const t of [...state.tables, state.light]) t.dispose();
    if (this.table.value !== this._empty && state.tables.some((t) => t.texture === this.table.value)) this.table.value = this._empty;
  }

  // The table's texels from three.js's depth texture of the light.
  texels(state, depth) {
    this._texels.uniforms.depthMap.value = depth;
    this._draw(this._texels, state.tables[0]);
    state.result = 0;
  }

  // The prefix sums along x, then y; the light's values; the table bound for the materials.
  build(state, light, { angularDiameter }) {
    if (!(angularDiameter >= 0 && angularDiameter < 90))
      throw new Error(`msm-three: soft.angularDiameter is the light's angular diameter in degrees, in [0, 90), not ${angularDiameter}`);
    const { width, height } = state.tables[0];
    const step = this._step.uniforms;
    let from = 0;
    for (const [axis, size] of [[0, width], [1, height]])
      for (let offset = 1; offset < size; offset *= 2) {
        step.source.value = state.tables[from].texture;
        step.offset.value.set(axis === 0 ? offset : 0, axis === 1 ? offset : 0);
        this._draw(this._step, state.tables[1 - from]);
        from = 1 - from;
      }
    state.result = from;
    // soft.h's spread: world units per unit of [-1,1] depth and per texel of three.js's orthographic map.
    const camera = light.shadow.camera;
    const worldPerDepth = 0.5 * (camera.far - camera.near);
    this._light.uniforms.light.value.set(Math.tan(0.5 * angularDiameter * Math.PI / 180), worldPerDepth,
      (camera.right - camera.left) / camera.zoom / width, (camera.top - camera.bottom) / camera.zoom / height);
    this._draw(this._light, state.light);
    this.table.value = state.tables[from].texture;
  }

  dispose() {
    for (const m of [this._texels, this._step, this._light]) m.dispose();
    this._empty.dispose();
  }
}
