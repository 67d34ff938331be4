// The technique table's names and aliases (msm/cpu/techniques.h).
#include "msm/cpu/techniques.h"
#include "msm/msm.h"
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
  try {
    find_technique("msm-hamburger-46");
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("unknown technique 'msm-hamburger-46' (did you mean msm-hamburger-64"), std::string::npos)
        << what;
  }
  try {
    find_technique("nope");
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).find("did you mean"), std::string::npos) << e.what();
  }
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
