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
// Point lights, which three.js's VSM leaves without a shadow: the package gives each a cube render
// target, into which three.js renders its six faces of radial distance (MeshDistanceMaterial, as
// for its own point shadows); the moments are made from it face by face, blurred over directions
// across the faces' seams (a cube texture samples seamlessly in WebGL 2) and bound where three.js
// binds a point light's cube map; the chunks gain a VSM getPointShadow.
// Moment soft shadows (msm-mssm4, ./soft.js): a directional light's depth becomes a 32-bit integer
// summed-area table, and its lookup is the renderer's soft.h flow.
import { ShaderChunk, VSMShadowMap, RawShaderMaterial, GLSL3, WebGLRenderTarget, WebGLCubeRenderTarget, BufferGeometry,
  BufferAttribute, Mesh, OrthographicCamera, FloatType, UnsignedByteType, RGBAFormat, RGFormat, LinearFilter, NearestFilter,
  ClampToEdgeWrapping, Vector2, DataTexture, DoubleSide } from 'three';
import { MSM_THREE_GLSL, MSM_THREE_SOFT_GLSL } from './generated/msm-glsl.js';
import { SoftShadowTables, DEFAULT_SOFT } from './soft.js';
import { MSM_BLUE_NOISE } from './generated/blue-noise.js';

// The techniques: name -> the id of src/glsl/msm_three.h (MSM_THREE_*).
export const TECHNIQUES = Object.freeze({
  'msm-hamburger-64': 0, // 4 x 16 bits after Θ4* (JCGT), Hamburger 4MSM
  'msm-hamburger-128': 1, // 4 x float (JCGT), Hamburger 4MSM
  'msm-nl-64': 2, // Φ of the float moments in 4 x 16 bits (HPG 2017), Algorithm 3
  'msm-nl-32': 3, // Φ in 32 bits (HPG 2017 §3.5) in an RGBA8 texture, a blue-noise dithered texel, Algorithm 3
  'msm-mssm4': 4, // moment soft shadows (JCGT §4): Θ4* in a 32-bit integer summed-area table, one directional light
});
const NL32 = TECHNIQUES['msm-nl-32'];
const MSSM4 = TECHNIQUES['msm-mssm4'];
export { DEFAULT_SOFT };

// The Gaussian blur: taps x taps texels, σ in texels (filter.h's defaults: the 2015 paper's kernel).
export const DEFAULT_BLUR = Object.freeze({ taps: 9, sigma: 2.4 });

// Over-darkening (JCGT §2.6, baselines.h's msm_overdarken): each lookup's shadow intensity is
// divided by the factor and clamped, so that leaking below 1 - factor is cut. The renderer's
// `overdarken` setting: 1 (off) by default, in [0.5, 1]; the JCGT paper uses 0.98.
export const DEFAULT_OVERDARKEN = 1;
const OVERDARKEN_MIN = 0.5;

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

// A cube face's texel (its gl_FragCoord) as the direction WebGL's cube sampling maps to it
// (msm_three_cube_direction: the major-axis table of the OpenGL ES 3.0 specification, 3.8.10).
const CUBE_DIRECTION = `
uniform int face;
vec3 cubeDirection(vec2 fragCoord, float size) { return msm_three_cube_direction(face, 2.0 * fragCoord / size - 1.0); }`;

// The filterable channels of a point light's cube face, from three.js's distance map:
// (distance - near) / (far - near), far the light's range; msm's depth is distance / range.
const GENERATE_CUBE = `${MSM_THREE_GLSL}${CUBE_DIRECTION}
uniform highp samplerCube distanceMap;
uniform float near;
uniform float range;
uniform int technique;
layout(location = 0) out vec4 channels;
void main() {
  float size = float(textureSize(distanceMap, 0).x);
  float stored = texture(distanceMap, cubeDirection(gl_FragCoord.xy, size)).x;
  channels = msm_three_generate(technique, msm_local_light_depth(mix(near, range, stored), range));
}`;

// One direction of the separable blur on a cube face: the taps step one texel along the face's
// own axis and continue onto the neighbouring face where they leave it.
const BLUR_CUBE = `${MSM_THREE_GLSL}${CUBE_DIRECTION}
uniform highp samplerCube source;
uniform highp sampler2D weights;
uniform int taps;
uniform vec2 direction;
uniform int technique;
uniform bool store;
layout(location = 0) out vec4 result;
void main() {
  float size = float(textureSize(source, 0).x);
  int r = taps / 2;
  vec4 sum = vec4(0.0);
  for (int k = 0; k < taps; ++k)
    sum += texelFetch(weights, ivec2(k, 0), 0).x * texture(source, cubeDirection(gl_FragCoord.xy + float(k - r) * direction, size));
  result = store ? msm_three_store(technique, sum) : sum;
}`;

// three.js's VSM getShadow, with the moments in place of mean and deviation: same signature,
// same shadow coordinates, bias and frustum test.
const GET_SHADOW = `
		${MSM_THREE_GLSL}
		#ifdef MSM_THREE_TECHNIQUE
		// The over-darkening factor (the package's overdarken), bound in the materials it marks.
		uniform float msmThreeOverdarken;
		#else
		#define MSM_THREE_TECHNIQUE 0
		#define msmThreeOverdarken 1.0
		#endif
		#if MSM_THREE_TECHNIQUE == 3
		uniform highp sampler2D msmThreeBlueNoise;
		#endif
		#if MSM_THREE_TECHNIQUE == 4
		${MSM_THREE_SOFT_GLSL}
		// The soft light's table (the package binds it) and soft.h's fetch of it.
		uniform highp usampler2D msmThreeSatTable;
		uvec4 msm_three_sat_fetch( int x, int y, int table ) {
			if ( x < 0 || y < 0 ) return uvec4( 0u );
			return texelFetch( msmThreeSatTable, ivec2( x, y ), 0 );
		}
		// The other lights under msm-mssm4 have msm-hamburger-64's maps.
		#define MSM_THREE_HARD_TECHNIQUE 0
		#else
		#define MSM_THREE_HARD_TECHNIQUE MSM_THREE_TECHNIQUE
		#endif
		// The light's visibility from the technique's shadow intensity, over-darkened as msm's renderer does.
		float msmThreeVisibility( float shadow, float shadowIntensity ) {
			return mix( 1.0, 1.0 - msm_overdarken( shadow, msmThreeOverdarken ), shadowIntensity );
		}
		float getShadow( sampler2D shadowMap, vec2 shadowMapSize, float shadowIntensity, float shadowBias, float shadowRadius, vec4 shadowCoord ) {
			float shadow = 0.0; // the technique's shadow intensity (0: lit)
			#if MSM_THREE_TECHNIQUE == 4
				// The soft light's map is its 1 x 1 texel of light values (soft.js); the others' are moments.
				if ( textureSize( shadowMap, 0 ) == ivec2( 1 ) ) {
					ivec2 size = textureSize( msmThreeSatTable, 0 );
					vec3 coord = shadowCoord.xyz / shadowCoord.w;
					coord.z += shadowBias;
					vec3 texels = vec3( coord.xy * vec2( size ), coord.z );
					vec2 slope = msm_three_depth_per_texel( dFdx( texels ), dFdy( texels ) );
					if ( coord.x >= 0.0 && coord.x <= 1.0 && coord.y >= 0.0 && coord.y <= 1.0 && coord.z <= 1.0 )
						shadow = msm_three_soft_shadow( size, texelFetch( shadowMap, ivec2( 0 ), 0 ), MSM_THREE_SOFT_KERNEL, coord, slope ).shadow;
					return msmThreeVisibility( shadow, shadowIntensity );
				}
			#endif
			shadowCoord.xyz /= shadowCoord.w;
			shadowCoord.z += shadowBias - msm_three_depth_bias( MSM_THREE_HARD_TECHNIQUE );
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
					shadow = msm_three_nl64_bilinear_shadow( texelFetch( shadowMap, i0, 0 ), texelFetch( shadowMap, ivec2( i1.x, i0.y ), 0 ),
						texelFetch( shadowMap, ivec2( i0.x, i1.y ), 0 ), texelFetch( shadowMap, i1, 0 ), f, shadowCoord.z );
				#elif MSM_THREE_TECHNIQUE == 3
					// The 32-bit texels decode alone: the texel nearest to the lookup moved by blue noise
					// in [-0.5, 0.5) texels (the renderer's dithered lookup, lookup.glsl).
					ivec2 last = textureSize( shadowMap, 0 ) - 1;
					vec2 t = shadowCoord.xy * vec2( last + 1 ) - 0.5;
					vec2 noise = texelFetch( msmThreeBlueNoise, ivec2( gl_FragCoord.xy ) & ( textureSize( msmThreeBlueNoise, 0 ) - 1 ), 0 ).xy;
					ivec2 i = clamp( ivec2( floor( t + noise ) ), ivec2( 0 ), last );
					shadow = msm_three_shadow( MSM_THREE_TECHNIQUE, texelFetch( shadowMap, i, 0 ), shadowCoord.z );
				#else
					shadow = msm_three_shadow( MSM_THREE_HARD_TECHNIQUE, texture( shadowMap, shadowCoord.xy ), shadowCoord.z );
				#endif
			}
			return msmThreeVisibility( shadow, shadowIntensity );
		}
`;

// A point light's lookup under VSM (three.js has none): the receiver's radial depth in msm's
// convention for local lights, the depth bias relative to the texel's size (a cube face spans
// 2 x distance); msm-mssm4's point lights have msm-hamburger-128's cubes (technique 1). The
// non-linear cubes are nearest-filtered, their texels read as the 2D lookup reads them, found by
// direction (msm_three_cube_texel_direction): the texels past a face's edge lie in the next face.
const GET_POINT_SHADOW = `
	#elif defined( SHADOWMAP_TYPE_VSM )
	float getPointShadow( samplerCube shadowMap, vec2 shadowMapSize, float shadowIntensity, float shadowBias, float shadowRadius, vec4 shadowCoord, float shadowCameraNear, float shadowCameraFar ) {
		const int technique = MSM_THREE_TECHNIQUE == 4 ? 1 : MSM_THREE_TECHNIQUE;
		float shadow = 1.0;
		vec3 lightToPosition = shadowCoord.xyz;
		float depth = msm_local_light_receiver_depth( length( lightToPosition ), shadowCameraFar, msm_three_depth_bias( technique ), 2.0 ) + shadowBias;
		if ( depth <= 1.0 ) {
			#if MSM_THREE_TECHNIQUE == 2
				// Four texels decoded to moments, those interpolated (the 2D lookup's bilinear weights).
				float size = float( textureSize( shadowMap, 0 ).x );
				vec2 f = fract( msm_three_cube_texel_coordinates( lightToPosition, size ) );
				shadow = 1.0 - msm_overdarken( msm_three_nl64_bilinear_shadow(
					texture( shadowMap, msm_three_cube_texel_direction( lightToPosition, size, vec2( 0.0, 0.0 ) ) ),
					texture( shadowMap, msm_three_cube_texel_direction( lightToPosition, size, vec2( 1.0, 0.0 ) ) ),
					texture( shadowMap, msm_three_cube_texel_direction( lightToPosition, size, vec2( 0.0, 1.0 ) ) ),
					texture( shadowMap, msm_three_cube_texel_direction( lightToPosition, size, vec2( 1.0, 1.0 ) ) ), f, depth ), msmThreeOverdarken );
			#elif MSM_THREE_TECHNIQUE == 3
				// One texel, the nearest moved by blue noise in [-0.5, 0.5) texels (as the 2D lookup).
				float size = float( textureSize( shadowMap, 0 ).x );
				vec2 noise = texelFetch( msmThreeBlueNoise, ivec2( gl_FragCoord.xy ) & ( textureSize( msmThreeBlueNoise, 0 ) - 1 ), 0 ).xy;
				shadow = 1.0 - msm_overdarken( msm_three_shadow( technique, texture( shadowMap, msm_three_cube_texel_direction( lightToPosition, size, noise ) ), depth ), msmThreeOverdarken );
			#else
				shadow = 1.0 - msm_overdarken( msm_three_shadow( technique, texture( shadowMap, lightToPosition ), depth ), msmThreeOverdarken );
			#endif
		}
		return mix( 1.0, shadow, shadowIntensity );
	}
`;

const VSM_BEGIN = '#elif defined( SHADOWMAP_TYPE_VSM )';
// The #else after it at the chunk's outer level (one tab: the ones inside getShadow are deeper).
const VSM_END = /\n\t#else\b/g;

// The point lights' sampler, declared for Basic shadows, and their lookup, called for PCF and Basic.
const POINT_SAMPLER = /#elif defined\( SHADOWMAP_TYPE_BASIC \)(\s*uniform samplerCube pointShadowMap)/;
const POINT_LOOKUP = /\n\t#elif defined\( SHADOWMAP_TYPE_BASIC \)\s*float getPointShadow\(/;
const POINT_CALL = /(NUM_POINT_LIGHT_SHADOWS[^\n]*)\( defined\( SHADOWMAP_TYPE_PCF \) \|\| defined\( SHADOWMAP_TYPE_BASIC \) \)/;

// shadowmap_pars_fragment with the VSM getShadow replaced and a VSM getPointShadow added;
// null where the chunk is not the one this package knows (another three.js release).
function momentChunk(original) {
  const begin = original.indexOf(VSM_BEGIN);
  if (begin < 0 || !POINT_SAMPLER.test(original) || !POINT_LOOKUP.test(original)) return null;
  VSM_END.lastIndex = begin;
  const end = VSM_END.exec(original);
  if (end === null) return null;
  const chunk = `${original.slice(0, begin + VSM_BEGIN.length)}\n${GET_SHADOW}${original.slice(end.index)}`;
  return chunk.replace(POINT_SAMPLER, '#elif defined( SHADOWMAP_TYPE_BASIC ) || defined( SHADOWMAP_TYPE_VSM )$1')
    .replace(POINT_LOOKUP, (m) => `\n${GET_POINT_SHADOW}${m}`);
}

// A chunk that calls getPointShadow for PCF and Basic shadows, calling it for VSM too.
function pointCallChunk(original) {
  return POINT_CALL.test(original) ? original.replace(POINT_CALL, '$1( defined( SHADOWMAP_TYPE_PCF ) || defined( SHADOWMAP_TYPE_BASIC ) || defined( SHADOWMAP_TYPE_VSM ) )') : null;
}

function mapTarget(width, height, filter, type = FloatType) {
  const target = new WebGLRenderTarget(width, height, {
    type, format: RGBAFormat, minFilter: filter, magFilter: filter, wrapS: ClampToEdgeWrapping, wrapT: ClampToEdgeWrapping,
    depthBuffer: false, generateMipmaps: false,
  });
  target.texture.name = 'msm-three';
  return target;
}

function cubeTarget(size, filter, type, depthBuffer) {
  return new WebGLCubeRenderTarget(size, {
    type, format: RGBAFormat, minFilter: filter, magFilter: filter, generateMipmaps: false, depthBuffer,
  });
}

function pass(fragmentShader, uniforms) {
  return new RawShaderMaterial({ glslVersion: GLSL3, vertexShader: VERTEX, fragmentShader, uniforms, depthTest: false, depthWrite: false });
}

// Every surface casts from both sides into the point lights' maps, as into msm's (its depth pass
// culls nothing): three.js's VSM renders the materials' front faces only (its PCF the back
// faces), and a caster cut open by the light's near plane (shadow.camera.near, 0.5 by default)
// would cast no shadow through the cut. Materials with their own shadowSide keep it. Returns
// what puts the materials back.
function castFromBothSides(scene) {
  const changed = [];
  scene.traverse((object) => {
    if (!object.material) return;
    for (const material of Array.isArray(object.material) ? object.material : [object.material])
      if (material.shadowSide === null) {
        material.shadowSide = DoubleSide;
        changed.push(material);
      }
  });
  return () => changed.forEach((material) => (material.shadowSide = null));
}

// The chunks the package replaces, as three.js has them, and what replaces them.
const CHUNKS = { shadowmap_pars_fragment: momentChunk, lights_fragment_begin: pointCallChunk, shadowmask_pars_fragment: pointCallChunk };
const originalChunks = Object.fromEntries(Object.keys(CHUNKS).map((name) => [name, ShaderChunk[name]]));
let activeInstances = 0;

export class MomentShadowMaps {
  // Switches renderer's shadows to moment shadow maps of `technique` (a key of TECHNIQUES).
  // soft: msm-mssm4's light (DEFAULT_SOFT: its angular diameter in degrees); overdarken: the
  // lookups' over-darkening factor (DEFAULT_OVERDARKEN).
  constructor(renderer, { technique = 'msm-hamburger-64', blur = DEFAULT_BLUR, soft = DEFAULT_SOFT, overdarken = DEFAULT_OVERDARKEN } = {}) {
    this.renderer = renderer;
    this.blur = { ...blur };
    this.soft = { ...soft };
    this._overdarken = { value: DEFAULT_OVERDARKEN }; // the lookups' uniform (_markMaterials binds it)
    this.overdarken = overdarken;
    this.supported = MomentShadowMaps.isSupported(renderer, true);
    this._technique = TECHNIQUES['msm-hamburger-64'];
    this.technique = technique;
    this._lights = new Map(); // light -> { threeMap, moments, scratch }
    this._points = new Map(); // point light -> { distance, moments, scratch, packed, stored } (cube render targets)
    this._softStates = new Map(); // msm-mssm4's light -> its tables and light texture (soft.js)
    this._softLight = null;
    this._warned = new Set();
    if (!this.supported) return;
    const chunks = Object.fromEntries(Object.entries(CHUNKS).map(([name, make]) => [name, make(originalChunks[name])]));
    const unknown = Object.keys(chunks).filter((name) => chunks[name] === null);
    if (unknown.length > 0) {
      console.warn(`msm-three: this three.js release's ${unknown.join(' and ')} are not the ones the package knows (VSM getShadow, point-light shadows); three.js's own shadows stay`);
      this.supported = false;
      return;
    }
    Object.assign(ShaderChunk, chunks);
    ++activeInstances;
    this._previousType = renderer.shadowMap.type;
    renderer.shadowMap.type = VSMShadowMap;
    this._triangle = new Mesh(new BufferGeometry().setAttribute('position', new BufferAttribute(new Float32Array(9), 3)));
    this._camera = new OrthographicCamera();
    this._weights = mapTarget(63, 1, NearestFilter);
    this._weightsPass = pass(WEIGHTS, { taps: { value: 9 }, sigma: { value: 2.4 } });
    this._generatePass = pass(GENERATE, { depthMap: { value: null }, technique: { value: 0 } });
    this._generateCubePass = pass(GENERATE_CUBE, {
      distanceMap: { value: null }, face: { value: 0 }, near: { value: 0 }, range: { value: 1 }, technique: { value: 0 },
    });
    this._blurCubePass = pass(BLUR_CUBE, {
      source: { value: null }, weights: { value: this._weights.texture }, taps: { value: 9 }, direction: { value: new Vector2() },
      face: { value: 0 }, technique: { value: 0 }, store: { value: false },
    });
    this._blurPass = pass(BLUR, {
      source: { value: null }, weights: { value: this._weights.texture }, taps: { value: 9 }, direction: { value: new Vector2() },
      technique: { value: 0 }, store: { value: false },
    });
    this._weightsKey = '';
    this._soft = new SoftShadowTables((material, target) => this._draw(material, target));
    // The dithered lookup's blue noise, bound in every marked material (_markMaterials).
    const noise = Uint8Array.from(atob(MSM_BLUE_NOISE.base64), (c) => c.charCodeAt(0));
    this._blueNoise = { value: new DataTexture(noise, MSM_BLUE_NOISE.size, MSM_BLUE_NOISE.size, RGFormat, UnsignedByteType) };
    this._blueNoise.value.needsUpdate = true;
    const shadowMap = renderer.shadowMap;
    this._render = shadowMap.render;
    const self = this;
    shadowMap.render = function (lights, scene, camera) {
      self._restore(lights);
      // msm-mssm4: the first shadow-casting directional light has soft shadows.
      self._softLight = self._technique === MSSM4 ? lights.find((l) => l.isDirectionalLight && l.castShadow) ?? null : null;
      // The moments are made from each light's depth texture when three.js's VSM blur first reads
      // it (its vertical pass): the blur then clears the light's map, depth included.
      const draw = renderer.renderBufferDirect;
      renderer.renderBufferDirect = function (camera_, scene_, geometry, material, ...rest) {
        const depth = material.uniforms?.shadow_pass?.value;
        if (depth?.isDepthTexture) self._generate(lights, depth);
        return draw.call(this, camera_, scene_, geometry, material, ...rest);
      };
      try {
        // The point lights after the others: three.js rebuilds every map in the first render after
        // the shadow type changed, and leaves a point light under VSM without one (and a warning).
        const points = lights.filter((l) => l.isPointLight);
        const needsUpdate = this.needsUpdate;
        self._render.call(this, lights.filter((l) => !l.isPointLight), scene, camera);
        if (points.length > 0) {
          this.needsUpdate = needsUpdate;
          self._preparePoints(points);
          const restoreSides = castFromBothSides(scene);
          try {
            self._render.call(this, points, scene, camera);
          } finally {
            restoreSides();
          }
        }
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

  get overdarken() {
    return this._overdarken.value;
  }
  set overdarken(factor) {
    if (!(typeof factor === 'number' && factor >= OVERDARKEN_MIN && factor <= 1))
      throw new Error(`msm-three: overdarken needs a factor in [${OVERDARKEN_MIN}, 1] (1: off), not ${factor}`);
    this._overdarken.value = factor;
  }

  // Back to three.js's own shadows (the type the renderer had before).
  dispose() {
    if (!this.supported) return;
    this._restore([...this._lights.keys(), ...this._softStates.keys()]);
    for (const { moments, scratch, packed } of this._lights.values()) {
      moments.dispose();
      scratch.dispose();
      packed?.dispose();
    }
    this._lights.clear();
    for (const state of this._softStates.values()) this._soft.release(state);
    this._softStates.clear();
    this._soft.dispose();
    for (const [light, { distance, moments, scratch, packed }] of this._points) {
      if ([distance, moments, packed].includes(light.shadow.map)) light.shadow.map = null; // three.js makes its own
      for (const target of [distance, moments, scratch, packed]) target?.dispose();
    }
    this._points.clear();
    this.renderer.shadowMap.render = this._render;
    this.renderer.shadowMap.type = this._previousType;
    if (--activeInstances === 0) Object.assign(ShaderChunk, originalChunks);
    for (const m of [this._weightsPass, this._generatePass, this._blurPass, this._generateCubePass, this._blurCubePass]) m.dispose();
    this._weights.dispose();
    this._blueNoise.value.dispose();
    this._triangle.geometry.dispose();
    this._marked?.forEach((material) => {
      delete material.defines.MSM_THREE_TECHNIQUE;
      material.onBeforeCompile = this._onBeforeCompile.get(material);
      material.needsUpdate = true;
    });
    this.supported = false;
  }

  // Puts three.js's own render target back on each light before it renders the depth.
  _restore(lights) {
    for (const light of lights) {
      const state = this._lights.get(light);
      if (state && (light.shadow.map === state.moments || light.shadow.map === state.packed)) light.shadow.map = state.threeMap;
      const soft = this._softStates.get(light);
      if (soft && light.shadow.map === soft.light) light.shadow.map = soft.threeMap;
    }
  }

  // Each shadow-casting point light renders its distances into the package's cube target.
  _preparePoints(points) {
    for (const light of points) {
      if (!light.castShadow) continue;
      const size = light.shadow.mapSize.x;
      let state = this._points.get(light);
      if (!state || state.distance.width !== size) {
        if (state) for (const target of [state.distance, state.moments, state.scratch, state.packed]) target?.dispose();
        else if (light.shadow.map !== null) light.shadow.map.dispose(); // three.js's own, from another shadow type
        const cube = (filter, depthBuffer) => cubeTarget(size, filter, FloatType, depthBuffer);
        state = { distance: cube(NearestFilter, true), moments: cube(LinearFilter, false), scratch: cube(LinearFilter, false) };
        state.stored = state.moments; // the cube the lights bind: the moments, or the technique's non-linear texels
        state.moments.texture.name = 'msm-three';
        // three.js disposes it instead of rendering where the shadow type changed in this render.
        state.distance.addEventListener('dispose', () => (state.rendered = false));
        this._points.set(light, state);
      }
      light.shadow.map = state.distance;
      state.rendered = light.shadow.autoUpdate || light.shadow.needsUpdate; // what three.js renders
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
    if (this._technique === MSSM4 && light === this._softLight) {
      const soft = this._soft.state(threeMap.width, threeMap.height, this._softStates.get(light));
      this._softStates.set(light, soft);
      Object.assign(soft, { threeMap, generated: true });
      const previousTarget = renderer.getRenderTarget();
      this._soft.texels(soft, depth);
      renderer.setRenderTarget(previousTarget);
      return;
    }
    if (this._technique === MSSM4)
      this._warnOnce(light, light.isDirectionalLight
        ? 'msm-mssm4 gives soft shadows to one directional light per renderer: this one has msm-hamburger-64\'s'
        : 'msm-mssm4 is for directional lights: this one has msm-hamburger-64\'s shadows');
    let state = this._lights.get(light);
    if (!state || state.moments.width !== threeMap.width || state.moments.height !== threeMap.height) {
      state?.moments.dispose();
      state?.scratch.dispose();
      state?.packed?.dispose();
      state = {
        moments: mapTarget(threeMap.width, threeMap.height, LinearFilter),
        scratch: mapTarget(threeMap.width, threeMap.height, NearestFilter),
      };
      this._lights.set(light, state);
    }
    state.threeMap = threeMap;
    state.generated = true;
    state.technique = this._technique === MSSM4 ? TECHNIQUES['msm-hamburger-64'] : this._technique;
    if (this._technique === NL32 && !state.packed) state.packed = mapTarget(threeMap.width, threeMap.height, NearestFilter, UnsignedByteType);
    const previousTarget = renderer.getRenderTarget();
    this._generatePass.uniforms.depthMap.value = depth;
    this._generatePass.uniforms.technique.value = state.technique;
    this._draw(this._generatePass, state.moments);
    renderer.setRenderTarget(previousTarget);
  }

  // Blur and store each generated moment map; the light's map is the moment map until the next
  // shadow render.
  _update(lights, scene) {
    const renderer = this.renderer;
    if (renderer.shadowMap.enabled !== true) return;
    this._markMaterials(scene);
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
      const soft = this._softStates.get(light);
      if (soft && light === this._softLight && soft.threeMap === light.shadow.map) {
        if (soft.generated) this._soft.build(soft, light, this.soft);
        soft.generated = false;
        light.shadow.map = soft.light;
        continue;
      }
      const state = this._lights.get(light);
      if (!state || state.threeMap !== light.shadow.map) continue;
      // A light that three.js did not update this frame (shadow.autoUpdate off) keeps its moments.
      if (state.generated) this._blur(state, taps);
      light.shadow.map = this._technique === NL32 ? state.packed : state.moments;
    }
    for (const light of lights) {
      const state = this._points.get(light);
      if (!state || light.shadow.map !== state.distance) continue;
      if (state.rendered) this._pointMoments(light, state, taps);
      light.shadow.map = state.stored;
    }
    renderer.setRenderTarget(previousTarget);
  }

  // A point light's moments, face by face from its distances, then blurred across the faces and
  // stored: the non-linear texels in a nearest-filtered cube of their own (RGBA8 for 32 bits), the
  // other techniques' in the linearly filtered moment cube.
  _pointMoments(light, state, taps) {
    state.rendered = false;
    let technique = this._technique;
    if (technique === MSSM4) {
      this._warnOnce(light, `${this.technique} has no cube maps: this point light's moments are msm-hamburger-128's`);
      technique = TECHNIQUES['msm-hamburger-128'];
    }
    state.stored = state.moments;
    if (technique === NL32 || technique === TECHNIQUES['msm-nl-64']) {
      const type = technique === NL32 ? UnsignedByteType : FloatType;
      if (state.packed?.texture.type !== type) {
        state.packed?.dispose();
        state.packed = cubeTarget(state.moments.width, NearestFilter, type, false);
        state.packed.texture.name = 'msm-three';
      }
      state.stored = state.packed;
    }
    const generate = this._generateCubePass.uniforms, blur = this._blurCubePass.uniforms;
    generate.distanceMap.value = state.distance.texture;
    generate.near.value = light.shadow.camera.near;
    generate.range.value = light.shadow.camera.far; // three.js's: the light's distance, else the camera's far
    generate.technique.value = technique;
    blur.taps.value = taps;
    blur.technique.value = technique;
    const faces = (material, target) => {
      for (let face = 0; face < 6; ++face) {
        material.uniforms.face.value = face;
        this.renderer.setRenderTarget(target, face);
        this.renderer.renderBufferDirect(this._camera, null, this._triangle.geometry, material, this._triangle, null);
      }
    };
    faces(this._generateCubePass, state.moments);
    blur.source.value = state.moments.texture;
    blur.direction.value.set(1, 0);
    blur.store.value = false;
    faces(this._blurCubePass, state.scratch);
    blur.source.value = state.scratch.texture;
    blur.direction.value.set(0, 1);
    blur.store.value = true;
    faces(this._blurCubePass, state.stored);
  }

  // The separable Gaussian of the generated moments, then their storage.
  _blur(state, taps) {
    state.generated = false;
    const blur = this._blurPass.uniforms;
    blur.taps.value = taps;
    blur.technique.value = state.technique;
    blur.source.value = state.moments.texture;
    blur.direction.value.set(1, 0);
    blur.store.value = false;
    this._draw(this._blurPass, state.scratch);
    blur.source.value = state.scratch.texture;
    blur.direction.value.set(0, 1);
    blur.store.value = true;
    this._draw(this._blurPass, this._technique === NL32 ? state.packed : state.moments); // 32 bits: RGBA8
  }

  // The receivers' programs read the technique as a define (part of three.js's program key).
  _markMaterials(scene) {
    this._marked ??= new Set();
    this._onBeforeCompile ??= new Map(); // a material's own hook, put back by dispose()
    const technique = this._technique;
    const blueNoise = this._blueNoise;
    const satTable = this._soft.table;
    const overdarken = this._overdarken;
    scene.traverse((object) => {
      if (!object.material) return;
      for (const material of Array.isArray(object.material) ? object.material : [object.material]) {
        material.defines ??= {};
        if (material.defines.MSM_THREE_TECHNIQUE === technique) continue;
        material.defines.MSM_THREE_TECHNIQUE = technique;
        material.needsUpdate = true;
        if (!this._onBeforeCompile.has(material)) {
          const own = material.onBeforeCompile;
          this._onBeforeCompile.set(material, own);
          material.onBeforeCompile = function (shader, renderer) {
            own.call(this, shader, renderer);
            shader.uniforms.msmThreeBlueNoise = blueNoise;
            shader.uniforms.msmThreeSatTable = satTable;
            shader.uniforms.msmThreeOverdarken = overdarken;
          };
        }
        this._marked.add(material);
      }
    });
  }
}
