// Moment shadow maps for three.js's WebGLRenderer, from msm's shared headers (bundled into
// ./generated/msm-glsl.js from include/msm/ and ./glsl/msm_three.h; no formula is written here).
//
// Integration: three.js's VSMShadowMap pipeline is kept for what it does well (a float depth
// texture per directional and spot light, rendered with every material's own depth material, the
// sampler bindings of the lights, the program variants). On top of it:
//  - renderer.shadowMap.render is wrapped: after three.js has rendered a light's depth, three
//    passes make the moment map from it (generate, horizontal and vertical Gaussian blur + storage)
//    and the light's shadow.map is pointed at the moment map until the next shadow render, so
//    that the lights bind it where they bound VSM's mean and deviation;
//  - ShaderChunk.shadowmap_pars_fragment's VSM getShadow() is replaced by the moment
//    reconstruction, so every standard material (and ShadowMaterial) reads it unchanged.
import { ShaderChunk, VSMShadowMap, RawShaderMaterial, GLSL3, WebGLRenderTarget, BufferGeometry, BufferAttribute, Mesh,
  OrthographicCamera, FloatType, RGBAFormat, RedFormat, LinearFilter, NearestFilter, ClampToEdgeWrapping, Vector2 } from 'three';
import { MSM_THREE_GLSL } from './generated/msm-glsl.js';

// The techniques: name -> the id of src/glsl/msm_three.h (MSM_THREE_*).
export const TECHNIQUES = Object.freeze({
  'msm-hamburger-64': 0, // 4 x 16 bits after Θ4* (JCGT), Hamburger 4MSM
  'msm-hamburger-128': 1, // 4 x float (JCGT), Hamburger 4MSM
  'msm-nl-64': 2, // Φ of the float moments in 4 x 16 bits (HPG 2017), Algorithm 3
});

// The Gaussian blur: taps x taps texels, σ in texels (filter.h's defaults: the 2015 paper's kernel).
export const DEFAULT_BLUR = Object.freeze({ taps: 9, sigma: 2.4 });

const VERTEX = `
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}`;

// The Gaussian weights of filter.h, one texel per tap.
const WEIGHTS = `${MSM_THREE_GLSL}
uniform int taps;
uniform float sigma;
layout(location = 0) out vec4 weight;
void main() { weight = vec4(msm_gaussian_weight(int(gl_FragCoord.x), taps, sigma), 0.0, 0.0, 0.0); }`;

// The filterable channels of each depth texel.
const GENERATE = `${MSM_THREE_GLSL}
uniform highp sampler2D depthMap;
uniform int technique;
layout(location = 0) out vec4 channels;
void main() { channels = msm_three_generate(technique, texelFetch(depthMap, ivec2(gl_FragCoord.xy), 0).x); }`;

// One direction of the separable blur (texels clamped to the edge); the vertical pass stores.
const BLUR = `${MSM_THREE_GLSL}
uniform highp sampler2D source;
uniform highp sampler2D weights;
uniform int taps;
uniform ivec2 direction;
uniform int technique;
uniform bool store;
layout(location = 0) out vec4 result;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 last = textureSize(source, 0) - ivec2(1);
  int r = taps / 2;
  vec4 sum = vec4(0.0);
  for (int k = 0; k < taps; ++k)
    sum += texelFetch(weights, ivec2(k, 0), 0).x * texelFetch(source, clamp(p + (k - r) * direction, ivec2(0), last), 0);
  result = store ? msm_three_store(technique, sum) : sum;
}`;

// three.js's VSM getShadow, with the moments in place of mean and deviation: same signature,
// same shadow coordinates, bias and frustum test.
const GET_SHADOW = `
		${MSM_THREE_GLSL}
		#ifndef MSM_THREE_TECHNIQUE
		#define MSM_THREE_TECHNIQUE 0
		#endif
		float getShadow( sampler2D shadowMap, vec2 shadowMapSize, float shadowIntensity, float shadowBias, float shadowRadius, vec4 shadowCoord ) {
			float shadow = 1.0;
			shadowCoord.xyz /= shadowCoord.w;
			shadowCoord.z += shadowBias - msm_three_depth_bias( MSM_THREE_TECHNIQUE );
			bool inFrustum = shadowCoord.x >= 0.0 && shadowCoord.x <= 1.0 && shadowCoord.y >= 0.0 && shadowCoord.y <= 1.0;
			if ( inFrustum && shadowCoord.z <= 1.0 ) {
				#if MSM_THREE_TECHNIQUE == 2
					// Non-linear texels are not interpolated as stored: four decoded to moments, those interpolated.
					ivec2 last = textureSize( shadowMap, 0 ) - 1;
					vec2 t = shadowCoord.xy * vec2( last + 1 ) - 0.5;
					ivec2 i0 = ivec2( floor( t ) );
					vec2 f = t - floor( t );
					ivec2 i1 = min( i0 + 1, last );
					i0 = max( i0, ivec2( 0 ) );
					vec4 m00 = msm_three_nl64_moments( texelFetch( shadowMap, i0, 0 ) );
					vec4 m10 = msm_three_nl64_moments( texelFetch( shadowMap, ivec2( i1.x, i0.y ), 0 ) );
					vec4 m01 = msm_three_nl64_moments( texelFetch( shadowMap, ivec2( i0.x, i1.y ), 0 ) );
					vec4 m11 = msm_three_nl64_moments( texelFetch( shadowMap, i1, 0 ) );
					shadow = 1.0 - msm_three_nl_shadow( mix( mix( m00, m10, f.x ), mix( m01, m11, f.x ), f.y ), shadowCoord.z );
				#else
					shadow = 1.0 - msm_three_shadow( MSM_THREE_TECHNIQUE, texture( shadowMap, shadowCoord.xy ), shadowCoord.z );
				#endif
			}
			return mix( 1.0, shadow, shadowIntensity );
		}
`;

const VSM_BEGIN = '#elif defined( SHADOWMAP_TYPE_VSM )';
// The #else after it at the chunk's outer level (one tab: the ones inside getShadow are deeper).
const VSM_END = /\n\t#else\b/g;

// shadowmap_pars_fragment with the VSM getShadow replaced; null where the chunk is not the one
// this package knows (another three.js release).
function momentChunk(original) {
  const begin = original.indexOf(VSM_BEGIN);
  if (begin < 0) return null;
  VSM_END.lastIndex = begin;
  const end = VSM_END.exec(original);
  if (end === null) return null;
  return `${original.slice(0, begin + VSM_BEGIN.length)}\n${GET_SHADOW}${original.slice(end.index)}`;
}

function floatTarget(width, height, filter, format = RGBAFormat) {
  const target = new WebGLRenderTarget(width, height, {
    type: FloatType, format, minFilter: filter, magFilter: filter, wrapS: ClampToEdgeWrapping, wrapT: ClampToEdgeWrapping,
    depthBuffer: false, generateMipmaps: false,
  });
  target.texture.name = 'msm-three';
  return target;
}

function pass(fragmentShader, uniforms) {
  return new RawShaderMaterial({ glslVersion: GLSL3, vertexShader: VERTEX, fragmentShader, uniforms, depthTest: false, depthWrite: false });
}

const originalChunk = ShaderChunk.shadowmap_pars_fragment;
let activeInstances = 0;

export class MomentShadowMaps {
  // Switches renderer's shadows to moment shadow maps of `technique` (a key of TECHNIQUES).
  constructor(renderer, { technique = 'msm-hamburger-64', blur = DEFAULT_BLUR } = {}) {
    this.renderer = renderer;
    this.blur = { ...blur };
    this.supported = MomentShadowMaps.isSupported(renderer, true);
    this._technique = TECHNIQUES['msm-hamburger-64'];
    this.technique = technique;
    this._lights = new Map(); // light -> { threeMap, moments, scratch }
    this._warned = new Set();
    if (!this.supported) return;
    const chunk = momentChunk(originalChunk);
    if (chunk === null) {
      console.warn('msm-three: this three.js release has no VSM getShadow in shadowmap_pars_fragment; three.js\'s own shadows stay');
      this.supported = false;
      return;
    }
    ShaderChunk.shadowmap_pars_fragment = chunk;
    ++activeInstances;
    this._previousType = renderer.shadowMap.type;
    renderer.shadowMap.type = VSMShadowMap;
    this._triangle = new Mesh(new BufferGeometry().setAttribute('position', new BufferAttribute(new Float32Array(9), 3)));
    this._camera = new OrthographicCamera();
    this._weights = floatTarget(63, 1, NearestFilter);
    this._weightsPass = pass(WEIGHTS, { taps: { value: 9 }, sigma: { value: 2.4 } });
    this._generatePass = pass(GENERATE, { depthMap: { value: null }, technique: { value: 0 } });
    this._blurPass = pass(BLUR, {
      source: { value: null }, weights: { value: this._weights.texture }, taps: { value: 9 }, direction: { value: new Vector2() },
      technique: { value: 0 }, store: { value: false },
    });
    this._weightsKey = '';
    const shadowMap = renderer.shadowMap;
    this._render = shadowMap.render;
    const self = this;
    shadowMap.render = function (lights, scene, camera) {
      self._restore(lights);
      // The moments are made from each light's depth texture when three.js's VSM blur first reads
      // it (its vertical pass): the blur then clears the light's map, depth included.
      const draw = renderer.renderBufferDirect;
      renderer.renderBufferDirect = function (camera_, scene_, geometry, material, ...rest) {
        const depth = material.uniforms?.shadow_pass?.value;
        if (depth?.isDepthTexture) self._generate(lights, depth);
        return draw.call(this, camera_, scene_, geometry, material, ...rest);
      };
      try {
        self._render.call(this, lights, scene, camera);
      } finally {
        renderer.renderBufferDirect = draw;
      }
      self._update(lights, scene);
    };
  }

  // WebGL 2 with float render targets and filterable float textures; `report` logs what lacks.
  static isSupported(renderer, report = false) {
    const missing = ['EXT_color_buffer_float', 'OES_texture_float_linear'].filter((e) => !renderer.extensions.has(e));
    if (missing.length > 0 && report)
      console.warn(`msm-three: WebGL 2 without ${missing.join(' and ')} (float render targets, filtered): moment shadow maps are off, three.js's own shadows stay`);
    return missing.length === 0;
  }

  get technique() {
    return Object.keys(TECHNIQUES).find((k) => TECHNIQUES[k] === this._technique);
  }
  set technique(name) {
    if (!(name in TECHNIQUES)) throw new Error(`msm-three: unknown technique '${name}' (one of ${Object.keys(TECHNIQUES).join(', ')})`);
    this._technique = TECHNIQUES[name];
  }

  // Back to three.js's own shadows (the type the renderer had before).
  dispose() {
    if (!this.supported) return;
    this._restore([...this._lights.keys()]);
    for (const { moments, scratch } of this._lights.values()) {
      moments.dispose();
      scratch.dispose();
    }
    this._lights.clear();
    this.renderer.shadowMap.render = this._render;
    this.renderer.shadowMap.type = this._previousType;
    if (--activeInstances === 0) ShaderChunk.shadowmap_pars_fragment = originalChunk;
    for (const m of [this._weightsPass, this._generatePass, this._blurPass]) m.dispose();
    this._weights.dispose();
    this._triangle.geometry.dispose();
    this._marked?.forEach((material) => {
      delete material.defines.MSM_THREE_TECHNIQUE;
      material.needsUpdate = true;
    });
    this.supported = false;
  }

  // Puts three.js's own render target back on each light before it renders the depth.
  _restore(lights) {
    for (const light of lights) {
      const state = this._lights.get(light);
      if (state && light.shadow.map === state.moments) light.shadow.map = state.threeMap;
    }
  }

  _warnOnce(light, message) {
    if (this._warned.has(light)) return;
    this._warned.add(light);
    console.warn(`msm-three: ${light.type} '${light.name || light.uuid}': ${message}`);
  }

  _draw(material, target) {
    this.renderer.setRenderTarget(target);
    this.renderer.renderBufferDirect(this._camera, null, this._triangle.geometry, material, this._triangle, null);
  }

  // Moments of the light whose depth texture is `depth`, into its moment map (before the blur).
  _generate(lights, depth) {
    const light = lights.find((l) => l.shadow?.map?.depthTexture === depth);
    if (!light || light.isPointLight) return;
    const renderer = this.renderer;
    if (renderer.state.buffers.depth.getReversed()) {
      this._warnOnce(light, 'a reversed depth buffer is not supported: three.js\'s VSM stays');
      return;
    }
    const threeMap = light.shadow.map;
    let state = this._lights.get(light);
    if (!state || state.moments.width !== threeMap.width || state.moments.height !== threeMap.height) {
      state?.moments.dispose();
      state?.scratch.dispose();
      state = {
        moments: floatTarget(threeMap.width, threeMap.height, LinearFilter),
        scratch: floatTarget(threeMap.width, threeMap.height, NearestFilter),
      };
      this._lights.set(light, state);
    }
    state.threeMap = threeMap;
    state.generated = true;
    const previousTarget = renderer.getRenderTarget();
    this._generatePass.uniforms.depthMap.value = depth;
    this._generatePass.uniforms.technique.value = this._technique;
    this._draw(this._generatePass, state.moments);
    renderer.setRenderTarget(previousTarget);
  }

  // Blur and store each generated moment map; the light's map is the moment map until the next
  // shadow render.
  _update(lights, scene) {
    const renderer = this.renderer;
    if (renderer.shadowMap.enabled !== true) return;
    this._markMaterials(scene);
    for (const light of lights)
      if (light.isPointLight && light.castShadow)
        this._warnOnce(light, 'point lights have no moment shadow map (three.js has no VSM for them either): no shadow');
    const previousTarget = renderer.getRenderTarget();
    const { taps, sigma } = this.blur;
    const key = `${taps}/${sigma}`;
    if (key !== this._weightsKey) {
      if (!(Number.isInteger(taps) && taps % 2 === 1 && taps >= 1 && taps <= 63 && sigma >= 1e-3 && sigma <= 1e3))
        throw new Error(`msm-three: blur needs odd taps in 1..63 and sigma in [1e-3, 1e3], not ${taps} and ${sigma}`);
      this._weightsPass.uniforms.taps.value = taps;
      this._weightsPass.uniforms.sigma.value = sigma;
      this._draw(this._weightsPass, this._weights);
      this._weightsKey = key;
    }
    for (const light of lights) {
      const state = this._lights.get(light);
      if (!state || state.threeMap !== light.shadow.map) continue;
      // A light that three.js did not update this frame (shadow.autoUpdate off) keeps its moments.
      if (state.generated) this._blur(state, taps);
      light.shadow.map = state.moments;
    }
    renderer.setRenderTarget(previousTarget);
  }

  // The separable Gaussian of the generated moments, then their storage.
  _blur(state, taps) {
    state.generated = false;
    const blur = this._blurPass.uniforms;
    blur.taps.value = taps;
    blur.technique.value = this._technique;
    blur.source.value = state.moments.texture;
    blur.direction.value.set(1, 0);
    blur.store.value = false;
    this._draw(this._blurPass, state.scratch);
    blur.source.value = state.scratch.texture;
    blur.direction.value.set(0, 1);
    blur.store.value = true;
    this._draw(this._blurPass, state.moments);
  }

  // The receivers' programs read the technique as a define (part of three.js's program key).
  _markMaterials(scene) {
    this._marked ??= new Set();
    const technique = this._technique;
    scene.traverse((object) => {
      if (!object.material) return;
      for (const material of Array.isArray(object.material) ? object.material : [object.material]) {
        material.defines ??= {};
        if (material.defines.MSM_THREE_TECHNIQUE === technique) continue;
        material.defines.MSM_THREE_TECHNIQUE = technique;
        material.needsUpdate = true;
        this._marked.add(material);
      }
    });
  }
}
