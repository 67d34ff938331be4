// Light leaking and over-darkening of the package's MSM 64 against three.js's VSMShadowMap at the
// same blur (the 2015 paper's ordering), on msm scenes built in three.js from msm's primitives
// (test/msm-scene.js), rendered in headless chromium (ANGLE on SwiftShader):
//  - `railing` and `fence` (scenes/*.json, their shadow maps framed explicitly),
//  - `overlap`: the 2015 paper's configuration, a high bar over a low slab 0.4 m above the ground.
//    Inside the slab's shadow, along the bar's shadow edge, a filter kernel holds both occluders'
//    depths while the receiver lies just behind the lower: Chebyshev's bound p_max = σ²/(σ² + (t - μ)²)
//    is about the bar's share of the kernel subtracted from 1, above three.js's cut at 0.3.
// Each shadow buffer (visibility, 320x180) is compared by `msm compare` with the 2015 paper's
// reference for filtered hard shadows, `msm render -t pcf` (PCF with the same Gaussian over the
// same map: the blur's own penumbrae are no error), and, printed beside it, with the ray-traced
// truth (`msm reference --effect hard`). light_leaking is the mean over all pixels of how much
// lighter the buffer is than the reference, over_darkening how much darker (their sum is the MAE).
// three.js's VSM remaps Chebyshev's bound from [0.3, 0.95] to [0, 1] (light bleeding reduction):
// it leaks only where the bound exceeds 0.3, and pays with darker penumbrae. The moments can make
// the same trade: the package's `overdarken` (msm_overdarken, JCGT §2.6, the renderer's setting).
// On the scenes where three.js's remap leaks less than MSM 64 without it (railing, fence), MSM 64
// is rendered over the factors OVERDARKEN in the same page (the factor changes between frames of
// one scene), and at the factor whose over-darkening comes nearest to VSM's without exceeding it,
// MSM 64 must leak less than VSM; its buffer there is also compared with `msm render --overdarken`
// of the same factor (the same function, so near-equal buffers). The spot and the point light's
// lookups over-darken as well (the example scene under each alone). The bounds (SCENES, LOCAL_*)
// are from measurement, each with its margin.
//   node test/leak.test.mjs path/to/msm OUT_DIR   (writes the scenes, buffers and error images there)
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launch, openPage } from './browser.mjs';
import { encodeExr, shadowBufferFromBase64, typedFromBase64 } from './exr.mjs';
import { serve } from './serve.mjs';

const webDir = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const [msm, out] = process.argv.slice(2);
if (!msm || !out) {
  console.error('usage: node test/leak.test.mjs path/to/msm OUT_DIR');
  process.exit(2);
}

const WIDTH = 320, HEIGHT = 180;
// VSM at the package's blur variance: three's VSM blur is a box over [-radius, radius] (variance
// radius² / 3), the package's the 9-tap σ = 2.4 Gaussian (variance 4.3 texels²): radius 3.6.
const VSM = { technique: 'vsm', vsmRadius: 3.6, vsmSamples: 17 };
const MSM = { technique: 'msm-hamburger-64' };
// The over-darkening factors of the sweep: 1 (off, the renderer's default), JCGT's 0.98, three.js's
// cut (its remap of the lit fraction 1 - s from [0.3, 0.95] to [0, 1] is s' = (s - 0.05) / 0.65,
// clamped: full shadow from s = 0.7 up, as the factor 0.7 gives) and beyond, to the renderer's
// setting's lowest factor, 0.5.
const OVERDARKEN = [1, 0.98, 0.9, 0.8, 0.7, 0.6, 0.5];

// The example scene under its spot or point light alone (160x90, a 256² map, 256² cube faces), with
// and without over-darkening. Measured: 7.4% (spot) and 24% (point) of the pixels darker at 0.5.
const LOCAL_LIGHTS = ['spot', 'point'];
const LOCAL_OVERDARKEN = 0.5;
const LOCAL_SIZE = { width: 160, height: 90, mapSize: 256 };
const LOCAL_DARKER_MIN = 0.02;

// msm's scene files allow // and /* */ comments (none of the scenes' strings holds one).
const withoutComments = (text) => text.replace(/\/\*[\s\S]*?\*\//g, '').replace(/\/\/.*$/gm, '');
const sceneFile = (name) => JSON.parse(withoutComments(readFileSync(join(webDir, '..', 'scenes', `${name}.json`), 'utf8')));
const framed = (description, framing) => ({ ...description, shadow_map: { framing: 'explicit', ...framing } });

const OVERLAP = {
  msm_scene: 1,
  name: 'overlap',
  camera: { position: [-2.2, 0.3, 0], target: [0, 0.05, 0], up: [0, 1, 0], fov_y_deg: 45, near: 0.05, far: 50 },
  light: { towards_light: [0.2, 1.0, 0.1], irradiance: [3, 3, 3], angular_extent_deg: 0 },
  objects: [
    { name: 'ground', primitive: { type: 'plane', size: [6, 6] }, material: { albedo: [0.7, 0.7, 0.7] } },
    { name: 'low slab', primitive: { type: 'box', size: [2.0, 0.04, 2.0] }, transform: { translate: [0, 0.4, 0] },
      material: { albedo: [0.6, 0.5, 0.4] } },
    { name: 'high bar', primitive: { type: 'box', size: [4.0, 0.04, 0.6] }, transform: { translate: [0.6, 3.0, 0.3] },
      material: { albedo: [0.6, 0.5, 0.4] } },
  ],
};

// Each scene's map holds every shadow the camera sees, its depth range the whole scene. Bounds:
//  - leakRatioMax: MSM 64's light leaking at most this times VSM's (the moments leak less);
//  - totalRatioMax and darkRatioMin: where three.js's remap leaks less, MSM 64's leaking +
//    over-darkening at most totalRatioMax times VSM's, and VSM's over-darkening at least
//    darkRatioMin times MSM 64's;
//  - matched (the sweep over OVERDARKEN): at the factor whose over-darkening comes nearest to VSM's
//    without exceeding it, MSM 64's leaking at most leakRatioMax times VSM's, and its buffer within
//    MAE renderMaeMax of `msm render -t msm-hamburger-64 --overdarken` of that factor, their signed
//    mean difference within ±renderMeanMax (the MAE is mostly the bars' silhouettes, which two
//    rasterizers cover differently; the signed mean is what tells the factors apart).
// Measured (SwiftShader; against msm's PCF): railing leaking 0.0369 vs 0.0249 (1.48x: the banner
// 6 cm behind the bars, short-range leaking), leaking + over-darkening ratio 0.842, VSM's
// over-darkening 21.9x; fence leaking 0.0048 vs 0.0042, total ratio 0.465, over-darkening 9.5x;
// overlap leaking ratio 0.219 (0.0014 vs 0.0065). The sweep: VSM's over-darkening is matched at
// overdarken 0.6 on the railing (MSM 64 0.0210 / 0.0137 against VSM's 0.0249 / 0.0200: leaking
// ratio 0.842; 0.7 leaks as much as VSM, 0.0249, and 0.5 over-darkens more, 0.0241) and 0.8 on the
// fence (0.0036 / 0.0053 against 0.0042 / 0.0081: 0.855; 0.7 over-darkens 0.0082). Against msm
// render --overdarken of that factor: MAE 0.0147, signed mean -0.0017 (railing; 0.0169 and
// +0.0081 at the package's 0.7, 0.0188 and -0.0151 at 0.5) and 0.0054, +0.0009 (fence; +0.0038 at
// 0.9, -0.0023 at 0.7); at the factor 1, 0.0091 and 0.0048.
const SCENES = [
  { name: 'railing', description: framed(sceneFile('railing'), { center: [0, 0.5, -0.5], extent: [6, 6], depth_range: [-4.5, 4.5] }),
    shadowSize: 512, totalRatioMax: 0.95, darkRatioMin: 5,
    matched: { leakRatioMax: 0.9, renderMaeMax: 0.0165, renderMeanMax: 0.004 } },
  { name: 'fence', description: framed(sceneFile('fence'), { center: [0, 0.5, 0], extent: [7, 7], depth_range: [-6, 6] }),
    shadowSize: 512, totalRatioMax: 0.6, darkRatioMin: 5,
    matched: { leakRatioMax: 0.9, renderMaeMax: 0.0065, renderMeanMax: 0.002 } },
  { name: 'overlap', description: framed(OVERLAP, { center: [0, 0.5, 0], extent: [5, 5], depth_range: [-3, 3] }), shadowSize: 256, leakRatioMax: 0.3 },
];

// `msm compare` of `test` against `reference`: { light_leaking, over_darkening, mae }.
function compare(reference, test, errorImage) {
  const json = execFileSync(msm, ['compare', '--json', '--error-image', errorImage, reference, test], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] });
  return JSON.parse(json);
}

const f = (x) => x.toFixed(5);
const SIZE_ARGS = ['--width', `${WIDTH}`, '--height', `${HEIGHT}`];
const run = (args) => execFileSync(msm, args, { stdio: ['ignore', 'ignore', 'inherit'] });
let failed = false;
const check = (ok, what) => {
  if (!ok) {
    console.error(`web-leak: FAILED: ${what} (images in ${out})`);
    failed = true;
  }
};

// The buffer `buffers[key]` of scene `name` as an EXR, compared with msm's PCF (and with the truth
// where `truth` is set).
function measure(buffers, name, key, truth = true) {
  const file = join(out, `${key}.exr`);
  writeFileSync(file, encodeExr(WIDTH, HEIGHT, buffers[key]));
  return {
    file,
    pcf: compare(join(out, `${name}-pcf`, 'pcf.exr'), file, join(out, `error-${key}-vs-pcf.png`)),
    truth: truth ? compare(join(out, `${name}-reference`, 'visibility.exr'), file, join(out, `error-${key}-vs-truth.png`)) : null,
  };
}
const overdarkenKey = (name, factor) => `${name}-${MSM.technique}${factor === 1 ? '' : `-overdarken-${factor}`}`;

// Each scene's buffers, in the order of the variants: MSM 64 at each factor (1 alone where the scene
// has no sweep), then three.js's VSM.
const variantsOf = ({ matched }) => [{ ...MSM, overdarken: matched ? OVERDARKEN : [1] }, VSM];

async function renderInBrowser() {
  const server = await serve(webDir);
  const browser = await launch();
  const errors = [];
  const buffers = {};
  const local = {};
  try {
    const page = await openPage(browser, `${server.url}/test/same-scene.html`, errors);
    await page.waitForFunction(() => window.msmReady === true);
    for (const light of LOCAL_LIGHTS)
      local[light] = (await page.evaluate((o) => window.msmOverdarkenedLight(o), { light, factors: [1, LOCAL_OVERDARKEN], ...LOCAL_SIZE }))
        .map((image) => typedFromBase64(Float32Array, image));
    for (const scene of SCENES) {
      const variants = variantsOf(scene);
      const list = (await page.evaluate(([d, o, v]) => window.msmShadowBuffers(d, o, v),
        [scene.description, { width: WIDTH, height: HEIGHT, shadowSize: scene.shadowSize }, variants])).map(shadowBufferFromBase64);
      variants[0].overdarken.forEach((factor, k) => (buffers[overdarkenKey(scene.name, factor)] = list[k]));
      buffers[`${scene.name}-${VSM.technique}`] = list[list.length - 1];
    }
  } finally {
    await browser.close();
    await server.close();
  }
  return { buffers, local, errors };
}

// The spot and the point light's lookups over-darken too: with LOCAL_OVERDARKEN no pixel of the
// example scene under that light alone is lighter than without, and at least LOCAL_DARKER_MIN of
// them are darker by more than 1e-3 (the penumbrae and the light leaking the factor cuts).
function checkLocal(local) {
  for (const light of LOCAL_LIGHTS) {
    const [off, on] = local[light];
    let lighter = 0, darker = 0, darkening = 0;
    for (let i = 0; i < off.length; i += 4) {
      const d = off[i] + off[i + 1] + off[i + 2] - (on[i] + on[i + 1] + on[i + 2]);
      if (d < -1e-5) ++lighter;
      if (d > 1e-3) ++darker;
      darkening += Math.max(d, 0);
    }
    const pixels = off.length / 4;
    console.log(`[web-leak] ${light} light alone, ${MSM.technique}, overdarken ${LOCAL_OVERDARKEN} against 1: ` +
      `${(100 * darker / pixels).toFixed(2)}% of the pixels darker, ${lighter} lighter, mean darkening ${(darkening / pixels).toFixed(5)}`);
    check(lighter === 0, `${light} light: ${lighter} pixels lighter with overdarken ${LOCAL_OVERDARKEN} than without`);
    check(darker >= LOCAL_DARKER_MIN * pixels, `${light} light: only ${darker} of ${pixels} pixels darker with overdarken ${LOCAL_OVERDARKEN}`);
  }
}

// The sweep: MSM 64's leaking and over-darkening at each factor of OVERDARKEN. A smaller factor
// darkens every pixel (msm_overdarken), so down the sweep leaking must not grow nor over-darkening
// shrink. At the factor whose over-darkening comes nearest to three.js's VSM's (`vsm`, against
// msm's PCF) without exceeding it, MSM 64 must leak at most matched.leakRatioMax times VSM's, and
// its buffer must be msm render's of that factor (its own MSM 64 with --overdarken) within MAE
// matched.renderMaeMax and signed mean ±matched.renderMeanMax.
function checkMatched({ name, shadowSize, matched }, buffers, vsm, msmAt1) {
  const sweep = OVERDARKEN.map((factor) => ({ factor, ...(factor === 1 ? msmAt1 : measure(buffers, name, overdarkenKey(name, factor), false)) }));
  console.log(`[web-leak] ${name}: ${MSM.technique}'s light leaking / over-darkening by overdarken: ` +
    sweep.map(({ factor, pcf }) => `${factor}: ${f(pcf.light_leaking)} / ${f(pcf.over_darkening)}`).join(', ') +
    `; three.js VSM ${f(vsm.light_leaking)} / ${f(vsm.over_darkening)}`);
  for (let k = 1; k < sweep.length; ++k) {
    const [milder, darker] = [sweep[k - 1], sweep[k]];
    check(darker.pcf.light_leaking <= milder.pcf.light_leaking + 1e-6 && darker.pcf.over_darkening >= milder.pcf.over_darkening - 1e-6,
      `${name}: overdarken ${darker.factor} leaks ${darker.pcf.light_leaking} and over-darkens ${darker.pcf.over_darkening}, ` +
      `against ${milder.pcf.light_leaking} and ${milder.pcf.over_darkening} at ${milder.factor}`);
  }
  const matching = sweep.filter(({ pcf }) => pcf.over_darkening <= vsm.over_darkening);
  const at = matching.reduce((best, s) => (best === null || s.pcf.over_darkening > best.pcf.over_darkening ? s : best), null);
  if (!at) {
    check(false, `${name}: ${MSM.technique} over-darkens more than three.js VSM's ${vsm.over_darkening} at every factor of ${OVERDARKEN.join(', ')}`);
    return;
  }
  const rendered = join(out, `${name}-msm-overdarken-${at.factor}`);
  run(['render', '--scene', join(out, `${name}.json`), '-t', MSM.technique, '--overdarken', `${at.factor}`, ...SIZE_ARGS,
    '--shadow-size', `${shadowSize}`, '-o', rendered]);
  const renderedFile = join(rendered, `${MSM.technique}.exr`);
  const againstRender = compare(renderedFile, at.file, join(out, `error-${overdarkenKey(name, at.factor)}-vs-render.png`));
  const renderVsPcf = compare(join(out, `${name}-pcf`, 'pcf.exr'), renderedFile, join(out, `error-render-${at.factor}-vs-pcf.png`));
  console.log(`[web-leak] ${name}: matched at overdarken ${at.factor}: ${MSM.technique} ${f(at.pcf.light_leaking)} / ` +
    `${f(at.pcf.over_darkening)} against three.js VSM ${f(vsm.light_leaking)} / ${f(vsm.over_darkening)} ` +
    `(leaking ratio ${(at.pcf.light_leaking / vsm.light_leaking).toFixed(3)}); msm render --overdarken ${at.factor}: ` +
    `${f(renderVsPcf.light_leaking)} / ${f(renderVsPcf.over_darkening)}, the package's buffer against it MAE ${f(againstRender.mae)} ` +
    `(signed mean ${f(againstRender.mean_error)})`);
  check(at.pcf.light_leaking <= matched.leakRatioMax * vsm.light_leaking,
    `${name}: at overdarken ${at.factor} (over-darkening ${at.pcf.over_darkening} <= three.js VSM's ${vsm.over_darkening}) ` +
    `${MSM.technique} leaks ${at.pcf.light_leaking}, more than ${matched.leakRatioMax} x three.js VSM's ${vsm.light_leaking}`);
  check(againstRender.mae <= matched.renderMaeMax && Math.abs(againstRender.mean_error) <= matched.renderMeanMax,
    `${name}: at overdarken ${at.factor} the package's buffer differs from msm render's by MAE ${againstRender.mae} ` +
    `(bound ${matched.renderMaeMax}), signed mean ${againstRender.mean_error} (bound ±${matched.renderMeanMax})`);
}

async function main() {
  mkdirSync(out, { recursive: true });
  const t0 = performance.now();
  for (const { name, description, shadowSize } of SCENES) {
    const file = join(out, `${name}.json`);
    writeFileSync(file, JSON.stringify(description, null, 1));
    run(['reference', '--scene', file, '--effect', 'hard', ...SIZE_ARGS, '--out', join(out, `${name}-reference`)]);
    run(['render', '--scene', file, '-t', 'pcf', ...SIZE_ARGS, '--shadow-size', `${shadowSize}`, '-o', join(out, `${name}-pcf`)]);
  }
  const t1 = performance.now();
  const { buffers, local, errors } = await renderInBrowser();
  const t2 = performance.now();
  errors.forEach((e) => console.error(e));
  check(errors.length === 0, 'the page reported errors');
  checkLocal(local);
  for (const scene of SCENES) {
    const { name, leakRatioMax, totalRatioMax, darkRatioMin } = scene;
    const msmAt1 = measure(buffers, name, overdarkenKey(name, 1)), vsm = measure(buffers, name, `${name}-${VSM.technique}`);
    const a = msmAt1.pcf, b = vsm.pcf, at = msmAt1.truth, bt = vsm.truth;
    console.log(`[web-leak] ${name}: light leaking / over-darkening against msm's PCF (same kernel): ${MSM.technique} ` +
      `${f(a.light_leaking)} / ${f(a.over_darkening)}, three.js VSM ${f(b.light_leaking)} / ${f(b.over_darkening)} ` +
      `(leaking ratio ${(a.light_leaking / b.light_leaking).toFixed(3)}, leaking + over-darkening ratio ${(a.mae / b.mae).toFixed(3)}); ` +
      `against the truth: ${f(at.light_leaking)} / ${f(at.over_darkening)} and ${f(bt.light_leaking)} / ${f(bt.over_darkening)}`);
    if (leakRatioMax !== undefined)
      check(a.light_leaking <= leakRatioMax * b.light_leaking,
        `${name}: ${MSM.technique} leaks ${a.light_leaking}, more than ${leakRatioMax} x three.js VSM's ${b.light_leaking}`);
    if (totalRatioMax !== undefined)
      check(a.mae <= totalRatioMax * b.mae,
        `${name}: ${MSM.technique}'s leaking + over-darkening ${a.mae} > ${totalRatioMax} x three.js VSM's ${b.mae}`);
    if (darkRatioMin !== undefined)
      check(b.over_darkening >= darkRatioMin * a.over_darkening,
        `${name}: three.js VSM over-darkens ${b.over_darkening}, less than ${darkRatioMin} x ${MSM.technique}'s ${a.over_darkening}`);
    if (scene.matched) checkMatched(scene, buffers, b, msmAt1);
  }
  const seconds = (t) => (t / 1000).toFixed(1);
  console.log(`[web-leak] time: msm reference and render ${seconds(t1 - t0)} s, the browser ${seconds(t2 - t1)} s, ` +
    `the comparisons (and msm render --overdarken) ${seconds(performance.now() - t2)} s`);
  if (failed) process.exit(1);
  console.log('web-leak: ok');
}

main().catch((e) => {
  console.error(`web-leak: ${e.stack ?? e}`);
  process.exit(1);
});
