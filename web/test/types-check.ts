// Compiled (not run) by test/package.test.mjs: the package's declarations describe its API.
import { MomentShadowMaps, TECHNIQUES, DEFAULT_BLUR, type Technique, type RendererLike } from 'msm-three';

declare const renderer: RendererLike;
const technique: Technique = 'msm-hamburger-64';
const moments = new MomentShadowMaps(renderer, { technique, blur: { taps: 9, sigma: DEFAULT_BLUR.sigma } });
moments.technique = 'msm-hamburger-128';
const id: 0 | 1 | 2 = TECHNIQUES[moments.technique];
const ok: boolean = MomentShadowMaps.isSupported(renderer, true) && moments.supported && id >= 0;
if (ok) moments.dispose();
