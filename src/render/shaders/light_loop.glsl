// The loop over the frame's lights, shared by the shading and the scattering pass (after frame.glsl).
//
// The frame's lights (FrameConfig::lights): a specialization constant, not frame.lights.x, because
// lavapipe (Mesa 22.3) re-optimizes and recompiles a shader at every bind whose loop bound is a
// uniform (it inlines the value to unroll the loop): about 0.8 s per frame of MSM-64 shading with
// Mesa's shader cache off, and a cache lookup per frame with it on (docs/results.md, "CPU-side costs").
layout(constant_id = MSM_SPEC_LIGHT_COUNT) const int kLightCount = 1;
const bool kOneLight = kLightCount == 1;

// Frames with one light evaluate it outside any loop: do { body(l) } while (!kOneLight && ++l <
// kLightCount), which NIR reduces to the body when the condition is the constant false. One call
// site: `kOneLight ? body(0) : for each l body(l)` ran the same, but NIR inlined and optimized both
// copies before removing the dead one (one-shot renders 0.15-0.2 s slower on lavapipe).
// NIR unrolls a loop only while its instruction cost times its trip count stays within
// max_unroll_iterations x 26 (nir_opt_loop_unroll.c), a one-trip loop too; a loop kept makes its
// counter, the lights[l] it indexes and the layer it reads per-lane vectors in llvmpipe (gathers, a
// variable layer). Past that limit (the four-moment scattering with the proportional β, the soft
// shadows' shading) a pass cost up to twice the instructions in a loop (docs/results.md, "One
// light, no loop"). With one light the layer is the constant 0: lavapipe fetches from a constant
// layer several times faster than from a variable one.
int current_layer = 0; // the light whose shadow map the lookups read, set before its lookups
#define shadow_layer (kOneLight ? 0 : current_layer)
