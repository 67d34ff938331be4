// msm::util::edit_distance and nearest_names (the CLI's "did you mean").
#include "msm/util/spelling.h"

#include <gtest/gtest.h>

namespace msm::util {
namespace {

TEST(Spelling, DistanceCountsEachEditOnce) {
  EXPECT_EQ(edit_distance("", ""), 0);
  EXPECT_EQ(edit_distance("abc", ""), 3);
  EXPECT_EQ(edit_distance("shadow-size", "shadow-size"), 0);
  EXPECT_EQ(edit_distance("shadow-sise", "shadow-size"), 1); // substitution
  EXPECT_EQ(edit_distance("shadowsize", "shadow-size"), 1);  // insertion
  EXPECT_EQ(edit_distance("rnder", "render"), 1);            // deletion
  EXPECT_EQ(edit_distance("rendre", "render"), 1);           // swap of neighbours
  EXPECT_EQ(edit_distance("Render", "render"), 0);           // case
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3);
  EXPECT_EQ(edit_distance("bogus", "scene"), 5);
  EXPECT_EQ(edit_distance("abc", "xyz"), edit_distance("xyz", "abc"));
}

TEST(Spelling, NearestNamesOnlyWhenNear) {
  const std::vector<std::string> options = {"width", "height", "shadow-size", "soft-kernel", "soft-scene", "msaa"};
  EXPECT_EQ(nearest_names("shadow-sise", options), std::vector<std::string>{"shadow-size"});
  EXPECT_EQ(nearest_names("msa", options), std::vector<std::string>{"msaa"});
  EXPECT_EQ(nearest_names("shadow", options), std::vector<std::string>{"shadow-size"}); // the start of one
  EXPECT_EQ(nearest_names("soft", options), (std::vector<std::string>{"soft-scene", "soft-kernel"}));
  EXPECT_TRUE(nearest_names("bogus", options).empty());
  EXPECT_TRUE(nearest_names("x", options).empty());
  EXPECT_EQ(did_you_mean("widht", options), " (did you mean width?)");
  EXPECT_EQ(did_you_mean("zzzzzz", options), "");
}

} // namespace
} // namespace msm::util
