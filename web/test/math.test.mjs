// The shared math on WebGL 2 agrees with the C++ library: msm_web_kernels (test/kernels.cpp)
// writes inputs and the C++ results of msm_web_kernel (test/kernels.h); test/math.html evaluates
// the same dispatcher, bundled from the same headers, in a fragment shader in headless chromium
// (ANGLE on SwiftShader); this compares them function by function with the bounds below, printing
// the measured maximum and 99.9th percentile ("[web-math]" lines) and the worst failing inputs.
//
//   node test/math.test.mjs path/to/msm_web_kernels WORK_DIR
//
// Why the two differ at all: WebGL 2 has neither `precise` nor fma() (shared.h's GL_ES mode), so
// ANGLE and the driver may contract a * b + c into an fma and reassociate; the C++ build has
// -ffp-contract=off. The exact operations (fma's emulation, the error-free transformations) stay
// exact only where the compiler keeps them apart, which fma's zero bound checks. Transcendentals
// (log, exp in Ψ4) are correctly rounded on neither side. Reconstructions from nearly singular
// Hankel matrices amplify last-bit differences near steep steps, as on the Vulkan device
// (src/core/gpu_math_test.cpp gives the same reasons; the bounds here are its bounds where the
// function is the same, and the measured SwiftShader values are quoted beside them).
// Also the point lights' cube lookup (msm_three.h's msm_three_cube_* functions) against WebGL 2's
// own cube sampling, the oracle for the OpenGL ES 3.0 major-axis table (checkCube).
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launch, openPage } from './browser.mjs';
import { serve } from './serve.mjs';

const webDir = resolve(dirname(fileURLToPath(import.meta.url)), '..');

// metric: 'ulp' (units in the last place), 'abs' (|web - cpu| / max(1, |cpu|)), 'unorm16' (the
// four 16-bit fields of u.xy, in steps; an exact tie k + 1/2 of the input may round either way),
// 'nl32' (the fields of the 32-bit non-linear word, in steps), 'words' (u's four words, in steps). outputs: the compared floats, a[0..3]
// then b[0..3]. max and p999 bound the largest per-input error and its 99.9th percentile.
const SPECS = {
  fma: { metric: 'ulp', outputs: [0], max: 0, p999: 0 },
  moments4: { metric: 'abs', outputs: [0, 1, 2, 3], max: 2.4e-7, p999: 2.4e-7 },
  theta4_star: { metric: 'abs', outputs: [0, 1, 2, 3], max: 1e-6, p999: 5e-7 },
  theta4_star_inverse: { metric: 'abs', outputs: [0, 1, 2, 3], max: 1e-6, p999: 5e-7 },
  pack_unorm16x4: { metric: 'unorm16', max: 0, p999: 0 },
  unpack_unorm16x4: { metric: 'ulp', outputs: [0, 1, 2, 3], max: 0, p999: 0 },
  apply_bias: { metric: 'abs', outputs: [0, 1, 2, 3], max: 5e-7, p999: 2.5e-7 },
  hamburger4_bounds: { metric: 'abs', outputs: [0, 1], max: 0.01, p999: 2e-4 },
  nl_from_moments: { metric: 'abs', outputs: [0, 1, 2, 3], max: 0.1, p999: 2e-4 },
  nl_moments_from: { metric: 'abs', outputs: [0, 1, 2, 3], max: 1e-6, p999: 5e-7 },
  nl_psi4: { metric: 'abs', outputs: [0], max: 1e-6, p999: 5e-7 },
  nl_psi4_inverse: { metric: 'ulp', outputs: [0], max: 192, p999: 128 },
  nl_pack64: { metric: 'unorm16', max: 1, p999: 1 },
  nl_unpack64: { metric: 'abs', outputs: [0, 1, 2, 3], max: 4e-6, p999: 2e-6 },
  nl_pack32: { metric: 'nl32', max: 1, p999: 1 },
  nl_unpack32: { metric: 'abs', outputs: [0, 1, 2, 3], max: 4e-6, p999: 2e-6 },
  nl_shadow: { metric: 'abs', outputs: [0], max: 0.1, p999: 2e-4 },
  // The package's techniques (src/glsl/msm_three.h), whose C++ results msm_web_kernels checks to
  // be the renderer's techniques': generation as moments4 and Θ4*, storage as UNORM16 rounding
  // and nl_pack64 (1 step at a rounding boundary: 1.5e-5), shading as hamburger4_bounds and nl_shadow.
  three_generate: { metric: 'abs', outputs: [0, 1, 2, 3], max: 1e-6, p999: 5e-7 },
  three_shadow: { metric: 'abs', outputs: [0], max: 0.01, p999: 2e-4 },
  three_store: { metric: 'abs', outputs: [0, 1, 2, 3], max: 1.6e-5, p999: 1.6e-5 },
  // Moment soft shadows (src/glsl/msm_three_soft.h): the table's texel (msm_web_kernels checks it
  // is the renderer's mssm4 texel) and its four words exactly; the receiver plane's slope; soft.h's
  // blocker search and filtered bound on quantized averages; the whole lookup over a 64² table.
  three_sat_texel: { metric: 'words', max: 0, p999: 0 },
  three_depth_per_texel: { metric: 'abs', outputs: [0, 1], max: 1e-6, p999: 1e-7 },
  soft_blocker4: { metric: 'abs', outputs: [0, 1], max: 0.01, p999: 2e-4 },
  soft_shadow4: { metric: 'abs', outputs: [0], max: 0.01, p999: 2e-4 },
  three_soft_shadow: { metric: 'abs', outputs: [0, 1, 2, 3, 4], max: 0.01, p999: 2e-4 },
  // The lookups' over-darkening (baselines.h, the package's overdarken): a division, clamped;
  // bit-identical on SwiftShader (GLSL ES allows division 2.5 ulp: a GPU may need 3).
  overdarken: { metric: 'ulp', outputs: [0], max: 0, p999: 0 },
  // The 64-bit non-linear map's bilinear lookup (msm_nl_bilinear, Algorithm 3) between two texels of
  // a lit plane near a point light, which msm_web_kernels checks to be lit in C++ (shadow <= 1e-3):
  // measured max 2.2e-10.
  three_nl64_bilinear: { metric: 'abs', outputs: [0], max: 1e-6, p999: 1e-7 },
};

const f32 = new Float32Array(1);
const u32 = new Uint32Array(f32.buffer);
const asFloat = (w) => ((u32[0] = w), f32[0]);
// Floats in the order of their values, as integers, so that their difference counts ulps.
const ordered = (w) => (w & 0x80000000 ? -(w & 0x7fffffff) : w);

function floatError(metric, web, cpu) {
  const x = asFloat(web), y = asFloat(cpu);
  if (Number.isNaN(x) || Number.isNaN(y)) return Number.isNaN(x) && Number.isNaN(y) ? 0 : Infinity;
  if (metric === 'ulp') return Math.abs(ordered(web) - ordered(cpu));
  return Math.abs(x - y) / Math.max(1, Math.abs(y));
}

const unorm16Fields = (u0, u1) => [u0 & 0xffff, u0 >>> 16, u1 & 0xffff, u1 >>> 16];
const nl32Fields = (u) => [u & 1023, (u >>> 10) & 511, (u >>> 19) & 127, u >>> 26];

// The error of one input: the largest over its compared outputs.
function inputError(spec, input, web, cpu) {
  if (spec.metric === 'unorm16') {
    const w = unorm16Fields(web[8], web[9]), c = unorm16Fields(cpu[8], cpu[9]);
    let e = 0;
    for (let i = 0; i < 4; ++i) {
      const v = Math.fround(asFloat(input[i]) * 65535); // the product as float rounds it
      const tie = v - Math.floor(v) === 0.5;
      const d = Math.abs(w[i] - c[i]);
      e = Math.max(e, tie && d <= 1 ? 0 : d);
    }
    return e;
  }
  if (spec.metric === 'words') return Math.max(...[8, 9, 10, 11].map((k) => Math.abs(web[k] - cpu[k])));
  if (spec.metric === 'nl32') {
    const w = nl32Fields(web[8]), c = nl32Fields(cpu[8]);
    return Math.max(...w.map((x, i) => Math.abs(x - c[i])));
  }
  return Math.max(...spec.outputs.map((o) => floatError(spec.metric, web[o], cpu[o])));
}

function quantile(sorted, q) {
  return sorted.length ? sorted[Math.floor(q * (sorted.length - 1))] : 0;
}

const show = (words) =>
  `a=(${[...words.slice(0, 4)].map(asFloat).map((x) => x.toPrecision(9)).join(', ')}) b=(${[...words.slice(4, 8)]
    .map(asFloat)
    .map((x) => x.toPrecision(9))
    .join(', ')}) u=(${[...words.slice(8, 12)].map((w) => '0x' + w.toString(16)).join(', ')})`;

// The point lights' cube lookup against WebGL 2's cube sampling (test/math.js, cubeCheck): every
// texel centre msm_three_cube_direction gives is sampled as that texel; a direction is sampled as
// the texel msm_three_cube_face_coordinates puts it in (but within 1e-3 texel of an edge); the
// bilinear lookup's texels (msm_three_cube_texel_direction) are those floor(t) + offset names on
// the direction's face, and where that lies past the face's edge, a texel on the edge of another
// face (the seam's other side). Returns whether all hold.
function checkCube({ size, runs }) {
  let ok = true;
  const texel = (v, k) => [v[4 * k], v[4 * k + 1], v[4 * k + 2]];
  for (const [name, { sampled, meant }] of Object.entries(runs)) {
    const n = sampled.length / 4;
    let wrong = 0, across = 0, ambiguous = 0;
    const examples = [];
    for (let k = 0; k < n; ++k) {
      const [sf, si, sj] = texel(sampled, k), [mf, mi, mj] = texel(meant, k);
      const inFace = mi >= 0 && mi < size && mj >= 0 && mj < size;
      let right;
      if (name !== 'texels' && meant[4 * k + 3] === 1) {
        ambiguous += 1;
        right = true;
      } else if (inFace) right = sf === mf && si === mi && sj === mj;
      else {
        across += 1;
        right = sf !== mf && sf < 6 && (si === 0 || si === size - 1 || sj === 0 || sj === size - 1);
      }
      if (!right) {
        wrong += 1;
        if (examples.length < 3) examples.push(`meant (${mf}, ${mi}, ${mj}), sampled (${sf}, ${si}, ${sj})`);
      }
    }
    const fine = wrong === 0 && (name === 'texels' || name === '0.5,0.5' || across >= 100);
    console.log(`[web-math] cube lookup (${size}² faces), ${name === 'texels' ? "every texel's centre" : name === '0.5,0.5' ? 'the texel holding a direction' : `offset (${name})`}: ` +
      `${wrong} of ${n} sampled other than meant (${across} past the face's edge, ${ambiguous} on an edge) ${fine ? 'ok' : 'FAILED'}` +
      (examples.length ? `\n  ${examples.join('\n  ')}` : ''));
    ok &&= fine;
  }
  return ok;
}

async function main() {
  const [tool, work] = process.argv.slice(2);
  if (!tool || !work) throw new Error('usage: node test/math.test.mjs MSM_WEB_KERNELS WORK_DIR');
  mkdirSync(work, { recursive: true });
  execFileSync(tool, [join(work, 'kernels.json'), join(work, 'kernels.bin')], { stdio: 'inherit' });
  const meta = JSON.parse(readFileSync(join(work, 'kernels.json'), 'utf8'));
  const bin = readFileSync(join(work, 'kernels.bin'));
  const words = new Uint32Array(bin.buffer, bin.byteOffset, bin.byteLength / 4);

  const server = await serve(webDir, { '/data/': resolve(work) });
  const browser = await launch();
  const errors = [];
  let run;
  try {
    const page = await openPage(browser, `${server.url}/test/math.html`, errors);
    await page.waitForFunction(() => typeof window.msmRunKernels === 'function');
    run = await page.evaluate(() => window.msmRunKernels());
  } finally {
    await browser.close();
    await server.close();
  }
  console.log(`[web-math] renderer: ${run.renderer}; program compiled and linked in ${run.compileMs.toFixed(0)} ms`);

  let failed = errors.length > 0;
  for (const e of errors) console.error(e);
  let offset = 0;
  for (const f of meta.functions) {
    const spec = SPECS[f.name];
    const n = 12 * f.count;
    const input = words.subarray(offset, offset + n);
    const cpu = words.subarray(offset + n, offset + 2 * n);
    offset += 2 * n;
    if (!spec) {
      console.error(`[web-math] ${f.name}: no bound stated`);
      failed = true;
      continue;
    }
    const b = Buffer.from(run.results[f.name], 'base64');
    const web = new Uint32Array(b.buffer, b.byteOffset, b.byteLength / 4);
    const errs = [];
    for (let i = 0; i < f.count; ++i) {
      const at = (w) => w.subarray(12 * i, 12 * i + 12);
      errs.push({ i, e: inputError(spec, at(input), at(web), at(cpu)) });
    }
    const sorted = errs.map((x) => x.e).sort((x, y) => x - y);
    const max = sorted[sorted.length - 1], p999 = quantile(sorted, 0.999);
    const differ = sorted.filter((e) => e > 0).length / f.count;
    const ok = max <= spec.max && p999 <= spec.p999;
    console.log(
      `[web-math] ${f.name} (${spec.metric}): max ${max.toPrecision(3)} p99.9 ${p999.toPrecision(3)} differ ${(100 * differ).toFixed(2)}%` +
        ` (bounds ${spec.max} / ${spec.p999}) ${ok ? 'ok' : 'FAILED'}`,
    );
    if (ok) continue;
    failed = true;
    errs.sort((x, y) => y.e - x.e);
    for (const { i, e } of errs.slice(0, 5)) {
      const at = (w) => w.subarray(12 * i, 12 * i + 12);
      console.log(`  input ${i} error ${e}\n    in:  ${show(at(input))}\n    web: ${show(at(web))}\n    cpu: ${show(at(cpu))}`);
    }
  }
  // The package's summed-area table (src/soft.js: texels, then prefix sums by recursive doubling in
  // RGBA32UI fragment passes) is sat.h's, word for word: WebGL 2's uint sums wrap modulo 2^32.
  const { width, height, offset: at } = meta.table;
  const want = words.subarray(at, at + 4 * width * height);
  const t = Buffer.from(run.packageTable, 'base64');
  const have = new Uint32Array(t.buffer, t.byteOffset, t.byteLength / 4);
  let differ = 0, wrapped = 0;
  for (let i = 0; i < want.length; ++i) differ += have[i] !== want[i] ? 1 : 0;
  for (let i = 4; i < want.length; i += 4) wrapped += want[i] < want[i - 4] ? 1 : 0; // a running sum along x went past 2^32
  console.log(`[web-math] the package's summed-area table (${width}x${height}, RGBA32UI passes): ${differ} of ${want.length} words ` +
    `differ from sat.h's (${wrapped} running sums wrapped around 2^32) ${differ === 0 && have.length === want.length ? 'ok' : 'FAILED'}`);
  if (differ > 0 || have.length !== want.length) failed = true;
  if (!checkCube(run.cube)) failed = true;
  if (failed) {
    console.error('web-math: FAILED');
    process.exit(1);
  }
  console.log('web-math: all functions within their bounds');
}

main().catch((e) => {
  console.error(`web-math: ${e.stack ?? e}`);
  process.exit(1);
});
