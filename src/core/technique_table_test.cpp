// The technique table (msm/cpu/techniques.h): names and aliases, its declarations against the
// shared header the shaders read (msm/techniques.h), its named parameters.
#include "msm/cpu/techniques.h"
#include "msm/msm.h"
#include "msm/techniques.h"
#include "msm/test/thrown.h"
#include "test_distributions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>
#include <stdexcept>
#include <string>

namespace msm {
namespace {

TEST(TechniqueTable, EveryAliasNamesOneTechniqueAndShadowsNone) {
  std::set<std::string_view> names, aliases;
  for (const Technique& t : techniques()) EXPECT_TRUE(names.insert(t.name).second) << t.name;
  ASSERT_FALSE(technique_aliases().empty());
  for (const TechniqueAlias& a : technique_aliases()) {
    EXPECT_TRUE(aliases.insert(a.alias).second) << a.alias << " twice";
    EXPECT_EQ(names.count(a.alias), 0u) << a.alias << " is also a technique's name";
    EXPECT_EQ(names.count(a.technique), 1u) << a.alias << " -> " << a.technique << ": no such technique";
    EXPECT_EQ(find_technique(a.alias).name, a.technique);
    EXPECT_EQ(canonical_technique_name(a.alias), a.technique);
    EXPECT_NE(technique_alias_list(a.technique).find(a.alias), std::string::npos);
  }
}

TEST(TechniqueTable, AliasesOfTheIssue) {
  EXPECT_EQ(find_technique("msm").name, "msm-hamburger-64");
  EXPECT_EQ(find_technique("vsm").name, "vsm-32");
  EXPECT_EQ(find_technique("evsm").name, "evsm4-64");
  EXPECT_EQ(find_technique("msm-nl").name, "msm-nl64");
  EXPECT_EQ(canonical_technique_name("msm6"), "msm6-96");
  EXPECT_EQ(canonical_technique_name("mssm"), "mssm4");
  EXPECT_EQ(canonical_technique_name("pcf"), "pcf");   // a name stays
  EXPECT_EQ(canonical_technique_name("nope"), "nope"); // and so does an unknown one
  EXPECT_EQ(technique_alias_list("pcf"), "");
}

TEST(TechniqueTable, UnknownNameSuggestsTheNearest) {
  const std::string what = test::thrown_message<std::invalid_argument>([] { find_technique("msm-hamburger-46"); });
  EXPECT_NE(what.find("unknown technique 'msm-hamburger-46' (did you mean msm-hamburger-64"), std::string::npos)
      << what;
  const std::string nope = test::thrown_message<std::invalid_argument>([] { find_technique("nope"); });
  EXPECT_NE(nope.find("unknown technique 'nope'"), std::string::npos) << nope;
  EXPECT_EQ(nope.find("did you mean"), std::string::npos) << nope;
}

// The table's categories are what the shaders' variant selection and the shared header's
// functions of the id say (the shaders read those), for every rendered technique.
TEST(TechniqueTable, CategoriesAgreeWithTheSharedHeader) {
  for (const Technique& t : techniques()) {
    SCOPED_TRACE(t.name);
    if (!t.rendered()) {
      EXPECT_EQ(t.id, -1);
      EXPECT_TRUE(t.on_cpu());
      continue;
    }
    ASSERT_GE(t.id, 0);
    EXPECT_EQ(&technique_by_id(t.id), &t);
    EXPECT_EQ(t.depth_based(), msm_technique_is_depth_based(t.id));
    EXPECT_EQ(t.soft(), msm_technique_is_soft(t.id));
    EXPECT_EQ(t.nonlinear(), msm_technique_is_nonlinear(t.id));
    EXPECT_EQ(t.area_light, msm_technique_is_area_light(t.id));
    EXPECT_EQ(t.six_moments, msm_technique_is_six_moments(t.id));
    EXPECT_EQ(t.scatters(), msm_technique_is_scattering(t.id));
    EXPECT_EQ(t.prefiltered_scattering(), msm_technique_is_prefiltered_scattering(t.id));
    EXPECT_EQ(t.scattering == Scattering::march, msm_technique_march_samples(t.id) > 0);
    EXPECT_EQ(t.scattering == Scattering::prefiltered_csm, t.id == MSM_TECH_SCATTER_CSM32);
    EXPECT_EQ(t.shading == ShadingVariant::soft, t.soft());
    EXPECT_EQ(t.shading == ShadingVariant::depth, t.depth_based());
    EXPECT_EQ(t.shading == ShadingVariant::nl64, t.id == MSM_TECH_NL64);
    EXPECT_EQ(t.shading == ShadingVariant::nl32, t.id == MSM_TECH_NL32);
    // Translucent occluders blend into one linear moment image.
    EXPECT_EQ(t.translucency, !t.depth_based() && !t.nonlinear() && !t.soft() && t.formats[1] == TexelFormat::none);
    // The per-pixel filters shade deferred by default.
    EXPECT_EQ(t.deferred_shading_default, t.id == MSM_TECH_PCF || t.area_light);
    EXPECT_EQ(t.default_soft_kernel > 0, t.area_light);
    EXPECT_LE(t.default_soft_kernel, t.max_soft_kernel);
    // Depth bias: the area lights' and the non-linear maps' constant, the depth maps' rounding, the
    // filtered moments' D16 rounding (config.h).
    const float bias = t.area_light      ? MSM_DEPTH_BIAS_AREA_LIGHT
                       : t.nonlinear()   ? MSM_DEPTH_BIAS_NONLINEAR
                       : t.depth_based() ? MSM_DEPTH_BIAS_DEPTH_MAP
                                         : MSM_DEPTH_BIAS_FILTERED;
    EXPECT_EQ(t.depth_bias, bias);
  }
}

// Every declared parameter's default is the papers' value in its slot of the vec4 the shaders read
// (msm_technique_default_params), inside its own range; slots and names are unique per technique.
TEST(TechniqueTable, ParametersDeclareTheShadersDefaults) {
  int declared = 0;
  for (const Technique& t : techniques()) {
    SCOPED_TRACE(t.name);
    std::set<int> slots;
    std::set<std::string_view> names;
    for (const Parameter* p : t.parameter_list()) {
      SCOPED_TRACE(p->name);
      ++declared;
      EXPECT_TRUE(slots.insert(p->slot).second);
      EXPECT_TRUE(names.insert(p->name).second);
      ASSERT_TRUE(p->slot >= 0 && p->slot < 4);
      EXPECT_EQ(p->default_value, t.default_params()[p->slot]);
      EXPECT_TRUE(p->accepts(p->default_value)) << p->range_text();
      EXPECT_FALSE(p->meaning.empty());
      EXPECT_EQ(&t.parameter(p->name), p);
      EXPECT_EQ(p->parse(p->value_text(p->default_value)), p->default_value);
    }
    EXPECT_EQ(parameter_vector(t, {}), t.default_params());
  }
  EXPECT_GT(declared, 40);
}

TEST(TechniqueTable, ParametersAreSetByNameAndValidated) {
  const Technique& scatter = find_technique("scatter-msm6-96");
  ParameterValues values;
  set_parameter(scatter, values, "beta=adaptive");
  set_parameter(scatter, values, "layers=4");
  set_parameter(scatter, values, "resampling=filtered");
  EXPECT_EQ(parameter_vector(scatter, values), glm::vec4(1.0f, 0.0f, float(MSM_SCATTERING_BETA_ADAPTIVE), 4.0f));
  EXPECT_EQ(parameter_value(scatter, values, "beta"), float(MSM_SCATTERING_BETA_ADAPTIVE));
  EXPECT_EQ(parameter_value(scatter, values, "fixed_beta"), 0.0f);
  auto refused = [](const Technique& t, std::string_view assignment, std::string_view message) {
    ParameterValues v;
    try {
      set_parameter(t, v, assignment);
      ADD_FAILURE() << assignment << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  refused(scatter, "layers=2.5", "layers = '2.5' is outside integer in [0, 16]");
  refused(scatter, "layers=17", "outside integer in [0, 16]");
  refused(scatter, "beta=adaptiv", "not one of proportional, fixed or adaptive (did you mean adaptive?)");
  refused(scatter, "layer=2", "unknown parameter 'layer' of scatter-msm6-96 (did you mean layers?)");
  refused(scatter, "layers", "write NAME=VALUE");
  refused(find_technique("msm"), "moment_bias=-1", "moment_bias = '-1' is outside [0, 1]");
  refused(find_technique("msm"), "moment_bias=nan", "outside [0, 1]");
  refused(find_technique("vsm"), "min_variance=0", "outside (0, 1]");
  refused(find_technique("pcf"), "x=1", "pcf has no parameters");
  // A value set in the vec4's slot is checked too.
  EXPECT_THROW(parameter_vector(find_technique("msm"), {{"moment_bias", -1.0f}}), std::invalid_argument);
  EXPECT_THROW(parameter_vector(find_technique("msm"), {{"bias", 0.0f}}), std::invalid_argument);
}

// The hard CSM technique (csm-4) on receivers at the far plane of a fitted map: the plate of
// SoftShadowTest.CssmShadowsReceiversOnTheFarPlane at depth 0 over the ground at depth 1 (csm-4
// runs on the CPU only, so the scene's depth pair through the technique's pipeline). On CSM's
// unscaled basis the square wave falls back through 1/2 at a depth difference of 1: shadow 0 there,
// where pcf gives 1 (measured before the fix: 0.0000). With the basis on MSM_CSM_BASIS_RANGE of the
// range (baselines.h) the far plane's shadow is that of a quarter-range difference on the unscaled
// basis (S(1 - t) = S(t)); the damped 4-term series gives 0.90 there. Asserted: the far-plane
// shadow equals the unscaled series at a difference of 1/4 (1e-5), and every difference in [1/3, 1]
// gets a shadow of at least 0.85 (measured worst 0.90); and the technique stays a lower bound of the
// exact shadow Z(z < zf) on random kernels (1e-5, as the CSM bound test of baselines_test.cpp).
TEST(TechniqueTable, HardCsmShadowsReceiversOnTheFarPlane) {
  const Technique& csm = find_technique("csm-4");
  ASSERT_TRUE(csm.on_cpu());
  const float one = 1.0f, plate = 0.0f;
  const float far = cpu::filtered_shadow(csm, std::span(&plate, 1), std::span(&one, 1), 1.0f);
  EXPECT_EQ(cpu::percentage_closer(std::span(&plate, 1), std::span(&one, 1), 1.0f), 1.0f);
  CsmParams p = msm_csm_default_params();
  p.terms = 4;
  const float quarter = msm_csm_shadow(msm_csm_moments(0.3f, 4), 0.3f + 0.25f, p);
  EXPECT_NEAR(far, quarter, 1e-5f);
  float worst = 1.0f;
  for (float z0 = 0.0f; z0 <= 2.0f / 3.0f; z0 += 1.0f / 24.0f)
    for (float d = 1.0f / 3.0f; z0 + d <= 1.0f + 1e-6f; d += 1.0f / 96.0f) {
      const float s = cpu::filtered_shadow(csm, std::span(&z0, 1), std::span(&one, 1), std::min(z0 + d, 1.0f));
      worst = std::min(worst, s);
    }
  std::printf("[csm-4 far plane] occluder 0, receiver 1: shadow %.4f (pcf 1); worst over differences in [1/3, 1] "
              "%.4f\n",
              far, worst);
  EXPECT_GE(far, 0.85f);
  EXPECT_GE(worst, 0.85f);

  std::mt19937_64 rng(15);
  float excess = 0.0f;
  for (int i = 0; i < 2000; ++i) {
    const test::Distribution d = test::random_distribution(rng, 0.0, 1.0);
    std::vector<float> z(d.z.begin(), d.z.end()), w(d.w.begin(), d.w.end());
    const float zf = std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
    excess = std::max(excess, cpu::filtered_shadow(csm, z, w, zf) - cpu::percentage_closer(z, w, zf));
  }
  EXPECT_LE(excess, 1e-5f) << "csm-4 must stay a lower bound";
}

} // namespace
} // namespace msm
