// The small helpers of include/msm/util/ that the tools and libraries share: list splitting, the
// output-directory check, the terminal progress bar and the clock.
#include "msm/util/clock.h"
#include "msm/util/output_dir.h"
#include "msm/util/progress.h"
#include "msm/util/text.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace msm {
namespace {

namespace fs = std::filesystem;
using Views = std::vector<std::string_view>;
using Strings = std::vector<std::string>;

TEST(Split, KeepsEmptyPartsSoThatACallerCanRefuseThem) {
  EXPECT_EQ(util::split("a,b,c", ','), (Views{"a", "b", "c"}));
  EXPECT_EQ(util::split("a,,b,", ','), (Views{"a", "", "b", ""}));
  EXPECT_EQ(util::split("", ','), (Views{""}));
  EXPECT_EQ(util::split("all:4:16", ':'), (Views{"all", "4", "16"}));
}

TEST(Split, NonemptyDropsEmptyParts) {
  EXPECT_EQ(util::split_nonempty("pcf,msm-hamburger-64", ','), (Strings{"pcf", "msm-hamburger-64"}));
  EXPECT_EQ(util::split_nonempty(",a,,b,", ','), (Strings{"a", "b"}));
  EXPECT_TRUE(util::split_nonempty("", ',').empty());
  EXPECT_TRUE(util::split_nonempty(",,", ',').empty());
}

TEST(OutputDir, CreatesTheDirectoryOrSaysWhyNot) {
  const fs::path root = fs::temp_directory_path() / fmt::format("msm-util-test-{}", ::getpid());
  fs::remove_all(root);
  EXPECT_EQ(util::prepare_output_dir(root / "a" / "b", "probe"), std::nullopt);
  EXPECT_TRUE(fs::is_directory(root / "a" / "b"));
  EXPECT_TRUE(fs::is_empty(root / "a" / "b")); // the probe file is gone

  std::ofstream(root / "file") << "x";
  const auto under_file = util::prepare_output_dir(root / "file" / "out", "probe");
  ASSERT_TRUE(under_file);
  EXPECT_TRUE(under_file->starts_with("cannot create the directory: ")) << *under_file;
  const auto is_file = util::prepare_output_dir(root / "file", "probe");
  ASSERT_TRUE(is_file);
  EXPECT_TRUE(is_file->starts_with("cannot create the directory") || *is_file == "not a directory") << *is_file;

  if (::geteuid() != 0) { // root writes everywhere
    fs::create_directories(root / "locked");
    fs::permissions(root / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_EQ(util::prepare_output_dir(root / "locked", "probe").value_or(""), "the directory is not writable");
    fs::permissions(root / "locked", fs::perms::owner_all);
  }
  fs::remove_all(root);
}

TEST(ProgressBar, FillsInProportionAndEstimatesTheRest) {
  EXPECT_EQ(util::progress_bar("msm x", 1, 4, 2.0, 8), "msm x [##      ]  25%  2.0 s, 6.0 s left ");
  EXPECT_EQ(util::progress_bar("msm x", 4, 4, 8.0, 4, "4/4 items  "),
            "msm x [####] 100%  4/4 items  8.0 s, 0.0 s left ");
  EXPECT_EQ(util::progress_bar("msm x", 0, 0, 0.0, 2), "msm x [##] 100%  0.0 s, 0.0 s left "); // no work: done
  EXPECT_EQ(util::progress_bar("msm x", 0, 3, 1.0, 3), "msm x [   ]   0%  1.0 s, 0.0 s left ");
}

TEST(Clock, SecondsSinceCountsForward) {
  const auto start = std::chrono::steady_clock::now();
  const double first = util::seconds_since(start);
  EXPECT_GE(first, 0.0);
  EXPECT_GE(util::seconds_since(start), first);
  EXPECT_NEAR(util::seconds_since(start - std::chrono::seconds(3)), 3.0, 1.0);
  EXPECT_NEAR(util::ms_since(start - std::chrono::seconds(3)), 3000.0, 1000.0);
}

} // namespace
} // namespace msm
