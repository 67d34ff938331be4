// One vocabulary across the subcommands: every command's options, walked on the app that msm
// itself builds (build_app), name the shared things by the vocabulary's names (vocabulary.h) and
// the render settings by their keys (msm/render/settings_schema.h).
#include "commands.h"
#include "vocabulary.h"

#include "msm/render/settings_schema.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

namespace msm::tool {
namespace {

struct Visible {
  std::string command, name, description;
};

// Every option of every command that its help shows (older spellings are hidden: group ""), by
// long name.
std::vector<Visible> visible_options(const CLI::App& app, const std::string& path = "msm") {
  std::vector<Visible> out;
  for (const CLI::Option* option : app.get_options()) {
    if (option->get_group().empty()) continue;
    for (const std::string& name : option->get_lnames()) out.push_back({path, "--" + name, option->get_description()});
  }
  for (const CLI::App* sub : app.get_subcommands({})) {
    std::vector<Visible> more = visible_options(*sub, path + " " + sub->get_name());
    out.insert(out.end(), more.begin(), more.end());
  }
  return out;
}

std::vector<Visible> msm_options() {
  CLI::App app;
  build_app(app);
  return visible_options(app);
}

TEST(CliVocabulary, NoCommandUsesAnotherNameForAVocabularyTerm) {
  std::map<std::string, std::string> synonym_of; // other name -> the term's name
  for (const Term& t : vocabulary())
    for (std::string_view other : t.other) synonym_of[std::string(other)] = std::string(t.name);
  for (const Visible& o : msm_options())
    if (auto it = synonym_of.find(o.name); it != synonym_of.end())
      ADD_FAILURE() << o.command << " " << o.name << ": the vocabulary's name is " << it->second;
}

TEST(CliVocabulary, EveryTermMeansTheSameInEveryCommand) {
  int terms_seen = 0;
  for (const Visible& o : msm_options()) {
    for (const Term& t : vocabulary()) {
      if (o.name != t.name) continue;
      ++terms_seen;
      EXPECT_TRUE(o.description.starts_with(t.meaning))
          << o.command << " " << o.name << " says \"" << o.description << "\", not \"" << t.meaning << "...\"";
    }
  }
  EXPECT_GT(terms_seen, 40); // the walk reached the commands
}

// A render setting has one name: its key with dashes, in every command that has it; never the key
// itself with its unit dropped or an underscore.
TEST(CliVocabulary, RenderSettingsAreNamedByTheirKeys) {
  std::map<std::string, std::string> key_of;
  for (const render::SettingDeclaration& s : render::setting_declarations()) {
    std::string key(s.key);
    key_of["--" + key] = render::setting_option_name(s);
    if (key.ends_with("_deg")) {
      std::string without_unit = key.substr(0, key.size() - 4);
      std::replace(without_unit.begin(), without_unit.end(), '_', '-');
      key_of["--" + without_unit] = render::setting_option_name(s);
    }
  }
  for (const Visible& o : msm_options())
    if (auto it = key_of.find(o.name); it != key_of.end() && it->first != it->second)
      ADD_FAILURE() << o.command << " " << o.name << ": the setting's option is " << it->second;
}

} // namespace
} // namespace msm::tool
