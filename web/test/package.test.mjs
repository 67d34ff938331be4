// The npm package as a user receives it: `npm pack` holds the ES module, its TypeScript
// declarations, the bundled GLSL and the README (and nothing of the tests), the declarations
// compile against a use of the API (test/types-check.ts, strict), and the packed module's exports
// are what the declarations promise.
import { execFileSync } from 'node:child_process';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const webDir = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const REQUIRED = ['package.json', 'README.md', 'src/index.js', 'src/index.d.ts', 'src/soft.js', 'src/generated/msm-glsl.js', 'src/generated/blue-noise.js'];
let failed = false;
const fail = (what) => {
  console.error(`web-package: FAILED: ${what}`);
  failed = true;
};

const [pack] = JSON.parse(execFileSync('npm', ['pack', '--dry-run', '--json', '--ignore-scripts'], { cwd: webDir, encoding: 'utf8' }));
const files = pack.files.map((f) => f.path).sort();
console.log(`[web-package] ${pack.filename}: ${files.join(', ')} (${pack.size} bytes packed)`);
for (const f of REQUIRED) if (!files.includes(f)) fail(`the package lacks ${f}`);
for (const f of files) if (f.startsWith('test/') || f.includes('node_modules')) fail(`the package holds ${f}`);

try {
  execFileSync(resolve(webDir, 'node_modules/.bin/tsc'), ['-p', 'test/tsconfig.json'], { cwd: webDir, stdio: 'inherit' });
  console.log('[web-package] declarations: test/types-check.ts compiles (strict)');
} catch {
  fail('test/types-check.ts does not compile against src/index.d.ts');
}

// The module's exports (it imports three, which node resolves from node_modules).
const module = await import(resolve(webDir, 'src/index.js'));
for (const name of ['MomentShadowMaps', 'TECHNIQUES', 'DEFAULT_BLUR', 'DEFAULT_SOFT', 'DEFAULT_OVERDARKEN'])
  if (!(name in module)) fail(`src/index.js does not export ${name}`);
if (JSON.stringify(Object.keys(module.TECHNIQUES)) !== JSON.stringify(['msm-hamburger-64', 'msm-hamburger-128', 'msm-nl-64', 'msm-nl-32', 'msm-mssm4']))
  fail(`TECHNIQUES is ${JSON.stringify(module.TECHNIQUES)}, not what index.d.ts declares`);
// The over-darkening factor, validated as msm's `overdarken` setting ([0.5, 1]) when it is given, the
// constructor's and the property's (a renderer without float targets: the package stays off, and says so).
const offRenderer = { extensions: { has: () => false }, shadowMap: { enabled: true, type: 0, render() {} } };
const warn = console.warn;
console.warn = () => {};
try {
  if (new module.MomentShadowMaps(offRenderer).overdarken !== module.DEFAULT_OVERDARKEN || module.DEFAULT_OVERDARKEN !== 1)
    fail('the over-darkening factor is not 1 (off, the renderer\'s default) by default');
  for (const factor of [0.5, 0.7, 1])
    if (new module.MomentShadowMaps(offRenderer, { overdarken: factor }).overdarken !== factor) fail(`overdarken ${factor} is not kept`);
  const refused = (what, make) => {
    try {
      make();
      fail(`${what} is accepted`);
    } catch (e) {
      if (!/overdarken needs a factor in \[0\.5, 1\]/.test(e.message)) fail(`${what}: ${e.message}`);
    }
  };
  for (const factor of [0.49, 1.01, 0, -1, NaN, Infinity, '0.9', null]) {
    refused(`overdarken ${String(factor)} in the options`, () => new module.MomentShadowMaps(offRenderer, { overdarken: factor }));
    const moments = new module.MomentShadowMaps(offRenderer, { overdarken: 0.9 });
    refused(`overdarken = ${String(factor)}`, () => (moments.overdarken = factor));
    if (moments.overdarken !== 0.9) fail(`overdarken = ${String(factor)} changed the factor to ${moments.overdarken}`);
  }
} finally {
  console.warn = warn;
}
if (!failed) console.log('[web-package] overdarken: 1 by default, factors outside [0.5, 1] refused');
if (failed) process.exit(1);
console.log('web-package: ok');
