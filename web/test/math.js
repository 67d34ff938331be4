// The browser half of the math test: evaluates msm_web_kernel (kernels.h, bundled from the shared
// headers) in a WebGL 2 fragment shader, one fragment per input, and returns the results. Inputs
// and results are KernelIOs as 12 uint32 words; floats travel as their bits, in RGBA32UI textures
// and render targets (integer formats are color-renderable in WebGL 2 without extensions, and
// keep every bit: no float conversion stands between the shader and the comparison).
import { MSM_KERNELS_GLSL } from './generated/kernels-glsl.js';
import * as THREE from 'three';
import { SoftShadowTables } from '../src/soft.js';

const WIDTH = 64;

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
  return { renderer, compileMs, results, packageTable: base64(packageTable(depths, width, height)) };
};
