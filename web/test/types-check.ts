// Compiled (not run) by test/package.test.mjs: the package's declarations describe its API.
import { MomentShadowMaps, TECHNIQUES, DEFAULT_BLUR, DEFAULT_SOFT, DEFAULT_OVERDARKEN, type Technique, type RendererLike } from 'msm-three';

declare const renderer: RendererLike;
const technique: Technique = 'msm-hamburger-64';
const moments = new MomentShadowMaps(renderer, { technique, blur: { taps: 9, sigma: DEFAULT_BLUR.sigma } });
moments.technique = 'msm-hamburger-128';
moments.overdarken = 0.98 * DEFAULT_OVERDARKEN;
const darker = new MomentShadowMaps(renderer, { overdarken: 0.9 });
darker.dispose();
const soft = new MomentShadowMaps(renderer, { technique: 'msm-mssm4', soft: { angularDiameter: 2 * DEFAULT_SOFT.angularDiameter } });
soft.soft.angularDiameter = 1;
const id: 0 | 1 | 2 | 3 | 4 = TECHNIQUES[moments.technique];
const ok: boolean = MomentShadowMaps.isSupported(renderer, true) && moments.supported && id >= 0;
if (ok) moments.dispose();
soft.dispose();
