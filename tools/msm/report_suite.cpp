#include "report_suite.h"

#include "commands.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

namespace msm::tool {
namespace {

using reference::Effect;

// The filtered hard-shadow techniques of the 2015 paper and JCGT 2017 at their storage sizes, from
// 16 (PCF, the reference of filtered hard shadows) to 128 bits per texel.
std::vector<SuiteTechnique> filtered_techniques() {
  return {{"pcf", {}},      {"vsm-32", {}},   {"evsm4-64", {}},         {"msm-hamburger-64", {}},
          {"msm-nl64", {}}, {"msm-nl32", {}}, {"msm-hamburger-128", {}}};
}

// Soft shadows of a directional area light: moment soft shadows and their baselines (JCGT §4).
std::vector<SuiteTechnique> soft_techniques() { return {{"mssm4", {}}, {"mssm6", {}}, {"vssm", {}}, {"pcss", {}}}; }

// Single scattering (JCGT §5): ray marching against the prefiltered moments.
std::vector<SuiteTechnique> scattering_techniques() {
  return {{"scatter-march-32", {}},
          {"scatter-march-128", {}},
          {"scatter-csm-32", {}},
          {"scatter-msm4-64", {}},
          {"scatter-msm6-96", {}}};
}

// Image-based lighting (Kneiphof): a probe cut into area lights with soft shadows, or into 256 point
// lights with hard ones, against the whole probe.
std::vector<SuiteTechnique> area_light_techniques() { return {{"mssm6", {}}, {"mssm4", {}}, {"pcss", {}}}; }
// (PCF per point light is a minute per frame on a CPU device: left out.)
std::vector<SuiteTechnique> point_light_techniques() { return {{"msm-hamburger-64", {}}}; }

std::vector<Suite> declared_suites() {
  Suite quick{"quick",
              "Two small scenes at 320 x 180: filtered hard shadows on the fence, soft shadows of the models; under a "
              "minute on a CPU device",
              {{"fence-filtered", "fence", Effect::filtered, 320, 180, 512, 64, filtered_techniques()},
               {"models-soft", "models", Effect::soft, 320, 180, 512, 64, soft_techniques()}}};
  Suite full{"full",
             "Every kind of shadow the renderer draws on the scenes that show its failure modes, at 640 x 360",
             {{"fence-filtered", "fence", Effect::filtered, 640, 360, 1024, 64, filtered_techniques()},
              {"railing-filtered", "railing", Effect::filtered, 640, 360, 1024, 64, filtered_techniques()},
              {"pillar_wall-filtered", "pillar_wall", Effect::filtered, 640, 360, 1024, 64, filtered_techniques()},
              {"stair-filtered", "stair", Effect::filtered, 640, 360, 1024, 64, filtered_techniques()},
              // The fence at other output and shadow-map sizes: cost against resolution.
              {"fence-filtered-320x180", "fence", Effect::filtered, 320, 180, 1024, 64, filtered_techniques()},
              {"fence-filtered-1280x720", "fence", Effect::filtered, 1280, 720, 1024, 64, filtered_techniques()},
              {"fence-filtered-map512", "fence", Effect::filtered, 640, 360, 512, 64, filtered_techniques()},
              {"fence-filtered-map2048", "fence", Effect::filtered, 640, 360, 2048, 64, filtered_techniques()},
              // A 4° light: its penumbra within every technique's kernel (the disc's own 10° is wider).
              {"disc-soft", "disc", Effect::soft, 640, 360, 1024, 64, soft_techniques(), 4.0f},
              {"models-soft", "models", Effect::soft, 640, 360, 1024, 64, soft_techniques()},
              {"trees-scattering", "trees", Effect::scattering, 320, 180, 1024, 32, scattering_techniques()},
              // One shadow map per light: the paper's 256² (Kneiphof §6).
              {"sky_probe-32-lights", "sky_probe", Effect::environment, 320, 180, 256, 256, area_light_techniques(),
               std::nullopt, 32},
              {"sky_probe-256-lights", "sky_probe", Effect::environment, 320, 180, 256, 256, point_light_techniques(),
               std::nullopt, 256}}};
  // The fence under one light of each kind the renderer draws, against the traced hard shadow (the
  // filtered penumbra is part of the error): the same texels per map, so the pass times compare
  // the kinds' per-light cost.
  for (const scene::LightKindInfo& kind : scene::light_kinds())
    if (kind.rendered)
      full.rows.push_back({fmt::format("fence-{}-hard", kind.name), "fence", Effect::hard, 640, 360, 1024, 1,
                           filtered_techniques(), std::nullopt, std::nullopt, kind.kind});
  // The street at night (scenes/street.json): its own lights together, two point lights among
  // columns, a spot light through a fence and faint moonlight, against the traced hard shadows.
  full.rows.push_back({"street-hard", "scenes/street.json", Effect::hard, 640, 360, 1024, 1, filtered_techniques()});
  // The papers' ratios at 1080p and 4K on a GPU (about 8 minutes with the truths): MSM's shading
  // against PCF's (JCGT Fig. 20's shape), the one-pass filter of the non-linear maps against the
  // three-pass of the others, prefiltered scattering against ray marching, soft shadows against PCSS.
  const std::vector<SuiteTechnique> gpu_filtered = {
      {"pcf", {}}, {"vsm-32", {}}, {"msm-hamburger-64", {}}, {"msm-nl64", {}}, {"msm-hamburger-128", {}}};
  const std::vector<SuiteTechnique> gpu_scattering = {
      {"scatter-march-128", {}}, {"scatter-msm4-64", {}}, {"scatter-msm6-96", {}}};
  Suite gpu{"gpu",
            "The papers' ratios at 1920 x 1080 and 3840 x 2160 on a GPU: filtered and soft shadows, single scattering",
            {{"fence-filtered-1080p", "fence", Effect::filtered, 1920, 1080, 2048, 16, gpu_filtered},
             {"fence-filtered-4k", "fence", Effect::filtered, 3840, 2160, 2048, 16, gpu_filtered},
             {"models-soft-1080p", "models", Effect::soft, 1920, 1080, 2048, 16, soft_techniques()},
             {"models-soft-4k", "models", Effect::soft, 3840, 2160, 2048, 16, soft_techniques()},
             {"trees-scattering-1080p", "trees", Effect::scattering, 1920, 1080, 1024, 8, gpu_scattering},
             {"trees-scattering-4k", "trees", Effect::scattering, 3840, 2160, 1024, 8, gpu_scattering}},
            10};
  // The math against the oracles: seconds on a CPU (the LP cases are the slow ones).
  const SuiteTests oracles{"The single-source math against the oracles", "src/core/msm_hamburger4_test",
                           "Hamburger4.EqualsJcgtAlgorithm1*"};
  quick.tests = {oracles};
  full.tests = {
      {"The single-source math against the oracles", "src/core/msm_hamburger4_test",
       "Hamburger4.Equals*:Hamburger4.ExactForUpToTwoDepths:Hausdorff4.Equals*"},
      {"The single-source math against the oracles", "src/core/msm_hamburger6_test", "Hamburger6.Equals*"},
      {"The single-source math against the oracles", "src/core/msm_trigonometric_test",
       "Trigonometric.EqualsLinearProgram"},
      {"The single-source math against the oracles", "src/core/msm_blocker_test", "Blocker.*EqualEquation4*"},
      {"The single-source math against the oracles", "src/core/msm_nonlinear_test",
       "NonLinear.Algorithm3EqualsHamburger4"},
      {"The single-source math against the oracles", "src/core/msm_edges_test",
       "Edges.Hamburger4AgainstAlgorithm1OnEveryStoragePath:Edges.Hamburger6AgainstAlgorithm1OnEveryStoragePath:"
       "Edges.NonLinearAgainstAlgorithm1"},
      {"The single-source math against the oracles", "src/core/msm_baselines_test",
       "Vsm.EqualsTheMomentOracleWithTwoMoments:Esm.EqualsTheLinearProgramForTheExponentialBasis"},
      {"The papers' leaking orderings (against PCF)", "src/render/msm_render_test",
       "RenderTest.LeakingOrderingsOfThePapersHold"},
      {"Every technique against the filtered ground truth", "src/render/msm_render_ground_truth_test",
       "GroundTruthTest.EveryTechniqueAgainstTheGroundTruth"},
      {"Soft shadows against the traced area light", "src/render/msm_render_soft_shadow_test",
       "SoftShadowTest.CloserToTheAreaLightThanHardShadows:SoftShadowTest.ModelsAndPillarBeforeBrickWall:"
       "SoftShadowTest.ConvolutionSoftShadowMaps:SoftShadowTest.RectangularLightsPenumbraeFollowTheirTwoExtents"},
      {"Spot and point lights against the ray tracer", "src/render/msm_render_local_lights_test",
       "LocalLightsRenderTest.SpotLightShadowsAgreeWithTheRayTracer:LocalLightsRenderTest."
       "SpotLightSoftShadowsAgreeWithTheRayTracer:LocalLightsRenderTest.PointLightShadowsAgreeWithTheRayTracer:"
       "LocalLightsRenderTest.PointLightErrorAlongCubeSeamsIsNoHigherThanElsewhere:LocalLightsRenderTest."
       "PointLightSoftShadowsAgreeWithTheRayTracer:LocalLightsRenderTest."
       "PointLightSoftErrorAlongCubeSeamsIsNoHigherThanElsewhere:LocalLightsRenderTest."
       "PcfUnderSpotAndPointLightsIsCloserToTheFilteredTruthThanToTheHard:LocalLightsRenderTest."
       "DepthTechniquesDoNotShadowTheLitFacetsOfACylinderUnderAPointLight:LocalLightsRenderTest."
       "SpotLightPrefilteredScatteringAgreesWithTheRayTracer"},
      {"The receiver plane on a faceted cylinder", "src/render/msm_render_ground_truth_test",
       "GroundTruthTest.DepthTechniquesDoNotShadowTheLitFacetsOfACylinderUnderADirectionalLight"},
      {"The 2015 ordering per light kind", "src/render/msm_render_light_kind_ordering_test", "LightKindOrderingTest.*"},
      {"Cascades: the box on a 500 m ground, the town, a slow pan, every technique",
       "src/render/msm_render_cascades_test",
       "CascadesRenderTest.BoxOnLargeGroundWithDefaultSettings:CascadesRenderTest.TownWithDefaultSettings:"
       "CascadesRenderTest.StabilisedCascadesShimmerLessInASlowPan:CascadesRenderTest."
       "DepthBoundsGiveTheNearCascadeFinerTexels:"
       "CascadesRenderTest.PenumbraKeepsItsWorldWidthAcrossCascades:"
       "CascadesRenderTest.EveryHardAndFilteredTechniqueWorksPerCascade"},
      {"Image-based lighting: the paper's orderings", "src/render/msm_render_ibl_test", "IblTest.*Orderings"},
      {"Probe lights: the plane's irradiance at every light count", "src/reference/msm_reference_environment_test",
       "Environment.AreaLightsKeepThePlanesIrradiance*"},
      {"Translucent occluders against the ray tracer", "src/render/msm_render_translucency_test",
       "TranslucencyTest.StackOfPlanesTransmitsAsTheRayTracerSays:TranslucencyTest.*UnderSpotAndPointLights*:"
       "TranslucencyTest.StairsUnderDirectionalSpotAndPointLightsAgainstTheRayTracer"},
      {"Single scattering against the ray tracer", "src/render/msm_render_scattering_ground_truth_test",
       "ScatteringGroundTruthTest.*"},
      {"Single scattering against the ray tracer", "src/render/msm_render_scattering_lights_test",
       "ScatteringLightsTest.TwoLightsAgreeWithTheGroundTruth"}};
  return {quick, full, gpu};
}

} // namespace

std::vector<std::string> suite_names() {
  std::vector<std::string> names;
  for (const Suite& s : declared_suites()) names.push_back(s.name);
  return names;
}

const Suite& find_suite(const std::string& name) {
  static const std::vector<Suite> suites = declared_suites();
  for (const Suite& s : suites)
    if (s.name == name) return s;
  throw UsageError(fmt::format("--suite {}: expected {}", name, fmt::join(suite_names(), ", ")));
}

} // namespace msm::tool
