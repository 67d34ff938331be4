// Moment shadow maps for three.js's WebGLRenderer (see README.md).

/**
 * The techniques, by name: 64-bit (Θ4*, 16-bit) and 128-bit (float) Hamburger 4MSM, 64- and 32-bit non-linear moments,
 * moment soft shadows (a 32-bit integer summed-area table of Θ4*; one directional light, the others get msm-hamburger-64).
 */
export declare const TECHNIQUES: Readonly<{
  'msm-hamburger-64': 0;
  'msm-hamburger-128': 1;
  'msm-nl-64': 2;
  'msm-nl-32': 3;
  'msm-mssm4': 4;
}>;
export type Technique = keyof typeof TECHNIQUES;

/** The Gaussian blur of the moment maps: taps x taps texels (odd, 1..63), σ in texels. */
export interface Blur {
  taps: number;
  sigma: number;
}
export declare const DEFAULT_BLUR: Readonly<Blur>;

/** msm-mssm4's area light: the directional light's angular diameter in degrees (a disc). */
export interface Soft {
  angularDiameter: number;
}
export declare const DEFAULT_SOFT: Readonly<Soft>;

/**
 * Over-darkening (JCGT §2.6, msm's `overdarken` setting): each lookup's shadow intensity divided by the factor and
 * clamped, which cuts light leaking below 1 - factor and darkens penumbrae. In [0.5, 1]; 1 (the default) is off.
 */
export declare const DEFAULT_OVERDARKEN: 1;

export interface MomentShadowMapsOptions {
  technique?: Technique;
  blur?: Blur;
  soft?: Soft;
  /** The over-darkening factor in [0.5, 1] (DEFAULT_OVERDARKEN); another value throws. */
  overdarken?: number;
}

/** The part of three's WebGLRenderer this package uses (three's own types need not be installed). */
export interface RendererLike {
  shadowMap: { enabled: boolean; type: number; render: (...args: unknown[]) => void };
  extensions: { has(name: string): boolean };
}

export declare class MomentShadowMaps {
  /** Switches the renderer's directional, spot and point light shadows to moment shadow maps. */
  constructor(renderer: RendererLike, options?: MomentShadowMapsOptions);
  /** False where WebGL 2 lacks float render targets (a console warning said so): three's shadows stay. */
  readonly supported: boolean;
  technique: Technique;
  blur: Blur;
  soft: Soft;
  /** The over-darkening factor in [0.5, 1] (1: off), applied from the next frame; another value throws. */
  overdarken: number;
  /** WebGL 2 with EXT_color_buffer_float and OES_texture_float_linear; report: warn on the console if not. */
  static isSupported(renderer: RendererLike, report?: boolean): boolean;
  /** Back to three's own shadows, of the type the renderer had before. */
  dispose(): void;
}
