// The technique table's names and aliases (msm/cpu/techniques.h).
#include "msm/cpu/techniques.h"

#include <gtest/gtest.h>

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

} // namespace
} // namespace msm
