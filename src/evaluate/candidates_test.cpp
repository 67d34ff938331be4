// Candidate lists (candidates.h) and the 37 functions (functions.h).
#include "msm/evaluate/candidates.h"
#include "msm/evaluate/functions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

namespace msm::evaluate {
namespace {

TEST(Functions, ThirtySevenDistinctFiniteFunctions) {
  ASSERT_EQ(candidate_functions().size(), 37u);
  std::set<std::string_view> names;
  for (const CandidateFunction& f : candidate_functions()) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    for (int i = 0; i <= 1000; ++i) EXPECT_TRUE(std::isfinite(f.value(i / 1000.0))) << f.name;
    EXPECT_EQ(find_function(f.name), int(&f - candidate_functions().data()));
  }
  EXPECT_FALSE(find_function("nope"));
}

TEST(Candidates, AllFourIsThePapersCount) {
  EXPECT_EQ(binomial(37, 4), 66045u);
  const std::vector<Candidate> all = parse_candidates("all:4");
  ASSERT_EQ(all.size(), 66045u);
  std::set<std::vector<int>> distinct;
  for (const Candidate& c : all) {
    ASSERT_EQ(c.functions.size(), 4u);
    EXPECT_TRUE(std::is_sorted(c.functions.begin(), c.functions.end()));
    distinct.insert(c.functions);
  }
  EXPECT_EQ(distinct.size(), all.size());
  EXPECT_EQ(all.front().name, "z+z2+z3+z4"); // rank 0: the power moments
  EXPECT_FALSE(all.front().listed);
}

TEST(Candidates, UnrankInvertsTheLexicographicOrder) {
  std::uint64_t rank = 0;
  for (int a = 0; a < 10; ++a)
    for (int b = a + 1; b < 10; ++b)
      for (int c = b + 1; c < 10; ++c) EXPECT_EQ(unrank_combination(10, 3, rank++), (std::vector<int>{a, b, c}));
  EXPECT_EQ(rank, binomial(10, 3));
}

TEST(Candidates, SamplesAreDistinctAndReproducible) {
  const std::vector<Candidate> a = parse_candidates("sample:4:500:9"), b = parse_candidates("sample:4:500:9");
  ASSERT_EQ(a.size(), 500u);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].functions, b[i].functions);
  EXPECT_NE(parse_candidates("sample:4:500:10")[0].functions, a[0].functions);
  EXPECT_EQ(parse_candidates("sample:2:666").size(), 666u); // all of C(37, 2)
}

TEST(Candidates, AliasesAndDuplicates) {
  const std::vector<Candidate> list = parse_candidates("named, all:4, z4+z3+z2+z");
  // power4 and trig4 are inside all:4 and z4+z3+z2+z is power4 again: evaluated once, first place.
  ASSERT_EQ(list.size(), 16u + 66045u - 2u);
  EXPECT_EQ(list[2].name, "z+z2+z3+z4");
  EXPECT_TRUE(list[2].has_alias("power4"));
  EXPECT_TRUE(list[2].listed);
  EXPECT_EQ(list[6].name, "sin2pi+cos2pi+sin4pi+cos4pi");
  EXPECT_TRUE(list[6].has_alias("trig4"));
  int closed = 0;
  for (const Candidate& c : list) closed += c.technique != Technique::lp ? 1 : 0;
  EXPECT_EQ(closed, 8);
  EXPECT_EQ(parse_candidates("power6")[0].m(), 6);
}

TEST(Candidates, BadListsSayWhatIsWrong) {
  const auto message = [](const char* spec) {
    try {
      parse_candidates(spec);
    } catch (const CandidateError& e) { return std::string(e.what()); }
    return std::string("no error");
  };
  EXPECT_NE(message("z+nope").find("unknown function 'nope'"), std::string::npos);
  EXPECT_NE(message("z+z2+z").find("appears twice, so the basis is linearly dependent"), std::string::npos);
  EXPECT_NE(message("all:9").find("K = 9 is outside [1, 8]"), std::string::npos);
  EXPECT_NE(message("sample:4:0").find("N = 0 is outside"), std::string::npos);
  EXPECT_NE(message("sample:4:x").find("'x' is not a non-negative integer"), std::string::npos);
  EXPECT_NE(message("").find("empty"), std::string::npos);
  EXPECT_NE(message("power4,,trig4").find("an empty item"), std::string::npos);
  EXPECT_NE(message("z+z2+z3+z4+z5+z6+sin1pi+cos1pi+exp2").find("at most 8"), std::string::npos);
}

} // namespace
} // namespace msm::evaluate
