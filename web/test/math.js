// The browser half of the math test: evaluates msm_web_kernel (kernels.h, bundled from the shared
// headers) in a WebGL 2 fragment shader, one fragment per input, and returns the results. Inputs
// and results are KernelIOs as 12 uint32 words; floats travel as their bits, in RGBA32UI textures
// and render targets (integer formats are color-renderable in WebGL 2 without extensions, and
// keep every bit: no float conversion stands between the shader and the comparison).
import { MSM_KERNELS_GLSL } from './generated/kernels-glsl.js';
import { MSM_THREE_GLSL } from '../src/generated/msm-glsl.js';
import * as THREE from 'three';
import { SoftShadowTables } from '../src/soft.js';

const WIDTH = 64;
const CUBE_SIZE = 16, CUBE_DIRECTIONS = 4096;

const VERTEX = `#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}`;

const FRAGMENT = `#version 300 es
${MSM_KERNELS_GLSL}
uniform highp usampler2D u_a;
uniform highp usampler2D u_b;
uniform highp usampler2D u_u;
uniform int u_function;
// The soft lookup's summed-area table (msm_web_kernels' soft_table), fetched as soft.h's flow asks.
uniform highp usampler2D u_table;
uvec4 msm_three_sat_fetch(int x, int y, int table) {
  if (x < 0 || y < 0) return uvec4(0u);
  return texelFetch(u_table, ivec2(x, y), 0);
}
layout(location = 0) out highp uvec4 o_a;
layout(location = 1) out highp uvec4 o_b;
layout(location = 2) out highp uvec4 o_u;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  KernelIO x = KernelIO(uintBitsToFloat(texelFetch(u_a, p, 0)), uintBitsToFloat(texelFetch(u_b, p, 0)),
                        texelFetch(u_u, p, 0));
  KernelIO r = msm_web_kernel(u_function, x);
  o_a = floatBitsToUint(r.a);
  o_b = floatBitsToUint(r.b);
  o_u = r.u;
}`;

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(shader)}`);
  return shader;
}

export function createKernelProgram(gl) {
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX));
  gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(`link: ${gl.getProgramInfoLog(program)}`);
  return program;
}

function texture(gl, width, height, data) {
  const t = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, t);
  gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32UI, width, height);
  if (data) gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, width, height, gl.RGBA_INTEGER, gl.UNSIGNED_INT, data);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  return t;
}

// words: count KernelIOs (12 words each) -> the kernel's results, in the same layout.
export function evaluate(gl, program, functionId, words, count, table) {
  const height = Math.ceil(count / WIDTH);
  const planes = [0, 1, 2].map(() => new Uint32Array(WIDTH * height * 4));
  for (let i = 0; i < count; ++i)
    for (let p = 0; p < 3; ++p) planes[p].set(words.subarray(12 * i + 4 * p, 12 * i + 4 * p + 4), 4 * i);
  const inputs = planes.map((plane) => texture(gl, WIDTH, height, plane));
  const outputs = [0, 1, 2].map(() => texture(gl, WIDTH, height, null));
  const fb = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  outputs.forEach((t, p) => gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + p, gl.TEXTURE_2D, t, 0));
  gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1, gl.COLOR_ATTACHMENT2]);
  if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) throw new Error('RGBA32UI targets incomplete');
  gl.useProgram(program);
  ['u_a', 'u_b', 'u_u'].forEach((name, p) => {
    gl.activeTexture(gl.TEXTURE0 + p);
    gl.bindTexture(gl.TEXTURE_2D, inputs[p]);
    gl.uniform1i(gl.getUniformLocation(program, name), p);
  });
  gl.activeTexture(gl.TEXTURE3);
  gl.bindTexture(gl.TEXTURE_2D, table);
  gl.uniform1i(gl.getUniformLocation(program, 'u_table'), 3);
  gl.uniform1i(gl.getUniformLocation(program, 'u_function'), functionId);
  gl.viewport(0, 0, WIDTH, height);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  const results = new Uint32Array(12 * count);
  const plane = new Uint32Array(WIDTH * height * 4);
  for (let p = 0; p < 3; ++p) {
    gl.readBuffer(gl.COLOR_ATTACHMENT0 + p);
    gl.readPixels(0, 0, WIDTH, height, gl.RGBA_INTEGER, gl.UNSIGNED_INT, plane);
    for (let i = 0; i < count; ++i) results.set(plane.subarray(4 * i, 4 * i + 4), 12 * i + 4 * p);
  }
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  [...inputs, ...outputs].forEach((t) => gl.deleteTexture(t));
  gl.deleteFramebuffer(fb);
  const error = gl.getError();
  if (error !== gl.NO_ERROR) throw new Error(`WebGL error 0x${error.toString(16)}`);
  return results;
}

function base64(words) {
  const bytes = new Uint8Array(words.buffer, words.byteOffset, words.byteLength);
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

// The package's summed-area table (src/soft.js's passes, in three.js) of the depth map `depths`
// (width x height floats): its words, as readPixels gives them (rows from y = 0).
function packageTable(depths, width, height) {
  const renderer = new THREE.WebGLRenderer({ canvas: document.createElement('canvas') });
  const triangle = new THREE.Mesh(new THREE.BufferGeometry().setAttribute('position', new THREE.BufferAttribute(new Float32Array(9), 3)));
  const camera = new THREE.OrthographicCamera();
  const tables = new SoftShadowTables((material, target) => {
    renderer.setRenderTarget(target);
    renderer.renderBufferDirect(camera, null, triangle.geometry, material, triangle, null);
  });
  const depth = new THREE.DataTexture(depths, width, height, THREE.RedFormat, THREE.FloatType);
  depth.needsUpdate = true;
  const state = tables.state(width, height);
  const gl = renderer.getContext();
  const words = new Uint32Array(4 * width * height);
  // The passes draw inside a render, as the package's do inside three.js's shadow render.
  const scene = new THREE.Scene();
  scene.onAfterRender = () => {
    tables.texels(state, depth);
    tables.build(state, { shadow: { camera } }, { angularDiameter: 1 });
    renderer.setRenderTarget(state.tables[state.result]);
    gl.readPixels(0, 0, width, height, gl.RGBA_INTEGER, gl.UNSIGNED_INT, words);
    renderer.setRenderTarget(null);
  };
  renderer.render(scene, camera);
  const error = gl.getError();
  tables.release(state);
  tables.dispose();
  depth.dispose();
  renderer.dispose();
  if (error !== gl.NO_ERROR) throw new Error(`WebGL error 0x${error.toString(16)} building the package's table`);
  return words;
}

// The point lights' cube lookup (msm_three.h) against WebGL 2's own cube sampling: a nearest-
// filtered RGBA32UI cube whose texels hold (face, i, j) is sampled by the package's functions.
// Per direction d (rows of RGBA32F) and offset o, out0: the texel the sampler returns, out1: the
// texel the functions mean, (msm_cube_face(d), floor(t + o)) with t msm_three_cube_texel_coordinates;
// offset (0.5, 0.5) samples d itself (the texel holding d: checks msm_three_cube_face_coordinates),
// the others msm_three_cube_texel_direction(d, size, o) (the lookups' texels); w of out1: 1 where
// d lies within 1e-3 texel of a texel's or a face's edge (either texel is right). u_texels: the
// directions are every texel's centre, msm_three_cube_direction(face, st) (the passes' texels).
const CUBE_FRAGMENT = `#version 300 es
${MSM_THREE_GLSL}
uniform highp usamplerCube u_cube;
uniform highp sampler2D u_directions;
uniform vec2 u_offset;
uniform bool u_texels;
layout(location = 0) out highp uvec4 o_sampled;
layout(location = 1) out highp ivec4 o_meant;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float size = float(textureSize(u_cube, 0).x);
  if (u_texels) {
    int n = int(size), face = p.x / n;
    ivec2 texel = ivec2(p.x % n, p.y);
    o_sampled = texture(u_cube, msm_three_cube_direction(face, (vec2(texel) + 0.5) * (2.0 / size) - 1.0));
    o_meant = ivec4(face, texel, 0);
    return;
  }
  vec3 d = texelFetch(u_directions, p, 0).xyz;
  int face = msm_cube_face(d);
  vec2 t = msm_three_cube_texel_coordinates(d, size) + u_offset;
  vec3 a = abs(d);
  float second = a.x + a.y + a.z - max(a.x, max(a.y, a.z)) - min(a.x, min(a.y, a.z));
  bool onEdge = abs(t.x - round(t.x)) < 1e-3 || abs(t.y - round(t.y)) < 1e-3 || second > (1.0 - 1e-5) * max(a.x, max(a.y, a.z));
  bool self = u_offset == vec2(0.5);
  o_sampled = texture(u_cube, self ? d : msm_three_cube_texel_direction(d, size, u_offset));
  o_meant = ivec4(face, ivec2(floor(t)), self && onEdge ? 1 : 0);
}`;

// The cube check's results: per offset (and the texels' centres), the sampled and meant texels.
function cubeCheck(gl, size, directions) {
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX));
  gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, CUBE_FRAGMENT));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(`link: ${gl.getProgramInfoLog(program)}`);
  const cube = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_CUBE_MAP, cube);
  gl.texStorage2D(gl.TEXTURE_CUBE_MAP, 1, gl.RGBA32UI, size, size);
  for (let face = 0; face < 6; ++face) {
    const texels = new Uint32Array(4 * size * size);
    for (let j = 0; j < size; ++j) for (let i = 0; i < size; ++i) texels.set([face, i, j, 0], 4 * (j * size + i));
    gl.texSubImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, 0, 0, size, size, gl.RGBA_INTEGER, gl.UNSIGNED_INT, texels);
  }
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  const count = directions.length / 4, height = Math.ceil(count / WIDTH);
  const rows = new Float32Array(4 * WIDTH * height);
  rows.set(directions);
  const input = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, input);
  gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, WIDTH, height);
  gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, WIDTH, height, gl.RGBA, gl.FLOAT, rows);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  const runs = [[0.5, 0.5], [0, 0], [1, 0], [0, 1], [1, 1], 'texels'];
  const results = {};
  for (const run of runs) {
    const [w, h] = run === 'texels' ? [6 * size, size] : [WIDTH, height];
    const targets = [gl.RGBA32UI, gl.RGBA32I].map((format) => {
      const t = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texStorage2D(gl.TEXTURE_2D, 1, format, w, h);
      return t;
    });
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    targets.forEach((t, k) => gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + k, gl.TEXTURE_2D, t, 0));
    gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1]);
    gl.useProgram(program);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, cube);
    gl.uniform1i(gl.getUniformLocation(program, 'u_cube'), 0);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, input);
    gl.uniform1i(gl.getUniformLocation(program, 'u_directions'), 1);
    gl.uniform2fv(gl.getUniformLocation(program, 'u_offset'), run === 'texels' ? [0, 0] : run);
    gl.uniform1i(gl.getUniformLocation(program, 'u_texels'), run === 'texels' ? 1 : 0);
    gl.viewport(0, 0, w, h);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    const sampled = new Uint32Array(4 * w * h), meant = new Int32Array(4 * w * h);
    gl.readBuffer(gl.COLOR_ATTACHMENT0);
    gl.readPixels(0, 0, w, h, gl.RGBA_INTEGER, gl.UNSIGNED_INT, sampled);
    gl.readBuffer(gl.COLOR_ATTACHMENT1);
    gl.readPixels(0, 0, w, h, gl.RGBA_INTEGER, gl.INT, meant);
    const n = run === 'texels' ? w * h : count;
    results[run === 'texels' ? run : run.join(',')] = { sampled: [...sampled.subarray(0, 4 * n)], meant: [...meant.subarray(0, 4 * n)] };
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    targets.forEach((t) => gl.deleteTexture(t));
    gl.deleteFramebuffer(fb);
  }
  [cube, input].forEach((t) => gl.deleteTexture(t));
  gl.deleteProgram(program);
  const error = gl.getError();
  if (error !== gl.NO_ERROR) throw new Error(`WebGL error 0x${error.toString(16)} in the cube check`);
  return results;
}

// Directions for the cube check: uniform over the sphere, and as many near a face's edge or corner.
function cubeDirections(count) {
  let seed = 12345;
  const random = () => ((seed = (Math.imul(seed, 1664525) + 1013904223) >>> 0) / 2 ** 32) * 2 - 1;
  const directions = new Float32Array(4 * count);
  for (let k = 0; k < count; ++k) {
    let d = [random(), random(), random()];
    if (k % 2 === 1) d = d.map((x) => (Math.abs(x) > 0.6 ? Math.sign(x) * (0.97 + 0.03 * Math.abs(random())) : x));
    directions.set([...d, 0], 4 * k);
  }
  return directions;
}

// Fetches /data/kernels.json and /data/kernels.bin (msm_web_kernels' output) and returns, per
// function, the results as base64 of their words, and the package's table of the soft lookup's
// depth map.
window.msmRunKernels = async () => {
  const gl = document.createElement('canvas').getContext('webgl2');
  if (!gl) throw new Error('no WebGL 2');
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const renderer = gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER);
  const meta = await (await fetch('/data/kernels.json')).json();
  const words = new Uint32Array(await (await fetch('/data/kernels.bin')).arrayBuffer());
  const t0 = performance.now();
  const program = createKernelProgram(gl);
  const compileMs = performance.now() - t0;
  const { width, height, offset: at } = meta.table;
  const table = texture(gl, width, height, words.subarray(at, at + 4 * width * height));
  let offset = 0;
  const results = {};
  for (const f of meta.functions) {
    const n = 12 * f.count;
    results[f.name] = base64(evaluate(gl, program, f.id, words.subarray(offset, offset + n), f.count, table));
    offset += 2 * n;
  }
  const depths = new Float32Array(words.buffer, words.byteOffset + 4 * meta.table.depths, width * height).slice();
  const cube = cubeCheck(gl, CUBE_SIZE, cubeDirections(CUBE_DIRECTIONS));
  return { renderer, compileMs, results, packageTable: base64(packageTable(depths, width, height)), cube: { size: CUBE_SIZE, runs: cube } };
};
