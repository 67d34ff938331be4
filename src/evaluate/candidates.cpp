// Parsing and expansion of candidate lists (candidates.h).
#include "msm/evaluate/candidates.h"

#include <algorithm>
#include <charconv>
#include <map>
#include <random>
#include <set>
#include <utility>

#include <fmt/format.h>

#include "msm/evaluate/functions.h"
#include "msm/util/text.h"

namespace msm::evaluate {
namespace {

struct Alias {
  std::string_view name;
  std::vector<std::string_view> functions;
};

const std::vector<Alias>& function_aliases() {
  static const std::vector<Alias> aliases{
      {"power2", {"z", "z2"}},
      {"power3", {"z", "z2", "z3"}},
      {"power4", {"z", "z2", "z3", "z4"}},
      {"power6", {"z", "z2", "z3", "z4", "z5", "z6"}},
      {"trig2", {"sin2pi", "cos2pi"}},
      {"trig3", {"sin2pi", "cos2pi", "sin4pi"}},
      {"trig4", {"sin2pi", "cos2pi", "sin4pi", "cos4pi"}},
      {"trig6", {"sin2pi", "cos2pi", "sin4pi", "cos4pi", "sin6pi", "cos6pi"}},
  };
  return aliases;
}

constexpr Technique kClosedForms[] = {Technique::pcf,   Technique::vsm,        Technique::esm,        Technique::evsm2,
                                      Technique::evsm4, Technique::hamburger4, Technique::hausdorff4, Technique::tmsm};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::uint64_t parse_count(std::string_view text, std::string_view item, std::string_view what) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty())
    throw CandidateError(fmt::format("candidate '{}': {} '{}' is not a non-negative integer", item, what, text));
  return value;
}

int parse_k(std::string_view text, std::string_view item) {
  const std::uint64_t k = parse_count(text, item, "K");
  if (k < 1 || k > std::uint64_t(kMaxFunctions))
    throw CandidateError(fmt::format("candidate '{}': K = {} is outside [1, {}]", item, k, kMaxFunctions));
  return int(k);
}

Candidate lp_candidate(std::vector<int> functions) {
  std::sort(functions.begin(), functions.end());
  Candidate c;
  c.technique = Technique::lp;
  for (int f : functions) c.name += (c.name.empty() ? "" : "+") + std::string(candidate_functions()[f].name);
  c.functions = std::move(functions);
  return c;
}

Candidate explicit_candidate(std::string_view item) {
  std::vector<int> functions;
  for (std::string_view name : util::split(item, '+')) {
    name = trim(name);
    const std::optional<int> index = find_function(name);
    if (!index) {
      std::string known;
      for (const CandidateFunction& f : candidate_functions())
        known += (known.empty() ? "" : ", ") + std::string(f.name);
      throw CandidateError(
          fmt::format("candidate '{}': unknown function '{}' (the 37 functions: {})", item, name, known));
    }
    if (std::find(functions.begin(), functions.end(), *index) != functions.end())
      throw CandidateError(fmt::format("candidate '{}': the function '{}' appears twice, so the basis is linearly "
                                       "dependent (a singular moment space)",
                                       item, name));
    functions.push_back(*index);
  }
  if (int(functions.size()) > kMaxFunctions)
    throw CandidateError(
        fmt::format("candidate '{}': {} functions, at most {}", item, functions.size(), kMaxFunctions));
  Candidate c = lp_candidate(std::move(functions));
  c.listed = true;
  return c;
}

} // namespace

std::string_view to_string(Technique technique) {
  switch (technique) {
  case Technique::lp: return "lp";
  case Technique::pcf: return "pcf";
  case Technique::vsm: return "vsm";
  case Technique::esm: return "esm";
  case Technique::evsm2: return "evsm2";
  case Technique::evsm4: return "evsm4";
  case Technique::hamburger4: return "hamburger4";
  case Technique::hausdorff4: return "hausdorff4";
  case Technique::tmsm: return "tmsm";
  }
  return "?";
}

bool Candidate::has_alias(std::string_view alias) const {
  return std::find(aliases.begin(), aliases.end(), alias) != aliases.end();
}

std::uint64_t binomial(int n, int k) {
  if (k < 0 || k > n) return 0;
  k = std::min(k, n - k);
  std::uint64_t result = 1;
  for (int i = 1; i <= k; ++i) result = result * std::uint64_t(n - k + i) / std::uint64_t(i); // exact at each step
  return result;
}

std::vector<int> unrank_combination(int n, int k, std::uint64_t rank) {
  std::vector<int> combination;
  int next = 0;
  for (int slot = 0; slot < k; ++slot)
    for (int candidate = next; candidate < n; ++candidate) {
      // Combinations that start with `candidate` in this slot.
      const std::uint64_t count = binomial(n - candidate - 1, k - slot - 1);
      if (rank < count) {
        combination.push_back(candidate);
        next = candidate + 1;
        break;
      }
      rank -= count;
    }
  return combination;
}

std::vector<Candidate> parse_candidates(std::string_view spec) {
  std::vector<Candidate> list;
  auto add_alias = [&](std::string_view alias) {
    for (const Alias& a : function_aliases())
      if (a.name == alias) {
        std::vector<int> functions;
        for (std::string_view f : a.functions) functions.push_back(*find_function(f));
        Candidate c = lp_candidate(std::move(functions));
        c.aliases.emplace_back(alias);
        c.listed = true;
        list.push_back(std::move(c));
        return true;
      }
    for (Technique t : kClosedForms)
      if (to_string(t) == alias) {
        Candidate c;
        c.technique = t;
        c.name = std::string(alias);
        c.listed = true;
        list.push_back(std::move(c));
        return true;
      }
    return false;
  };

  if (trim(spec).empty()) throw CandidateError("the candidate list is empty");
  for (std::string_view item : util::split(spec, ',')) {
    item = trim(item);
    if (item.empty()) throw CandidateError(fmt::format("candidate list '{}': an empty item", spec));
    if (item == "named") {
      for (const Alias& a : function_aliases()) add_alias(a.name);
      for (Technique t : kClosedForms) add_alias(to_string(t));
    } else if (item.starts_with("all:")) {
      const int k = parse_k(item.substr(4), item);
      const std::uint64_t count = binomial(kFunctionCount, k);
      for (std::uint64_t rank = 0; rank < count; ++rank)
        list.push_back(lp_candidate(unrank_combination(kFunctionCount, k, rank)));
    } else if (item.starts_with("sample:")) {
      const std::vector<std::string_view> parts = util::split(item, ':');
      if (parts.size() != 3 && parts.size() != 4)
        throw CandidateError(fmt::format("candidate '{}': expected sample:K:N or sample:K:N:SEED", item));
      const int k = parse_k(parts[1], item);
      const std::uint64_t n = parse_count(parts[2], item, "N");
      const std::uint64_t seed = parts.size() == 4 ? parse_count(parts[3], item, "SEED") : 1;
      const std::uint64_t total = binomial(kFunctionCount, k);
      if (n < 1 || n > total)
        throw CandidateError(fmt::format("candidate '{}': N = {} is outside [1, C(37, {}) = {}]", item, n, k, total));
      // Distinct ranks, uniformly (Floyd's algorithm: N draws, no rejection loop).
      std::mt19937_64 rng(seed);
      std::set<std::uint64_t> ranks;
      for (std::uint64_t j = total - n; j < total; ++j) {
        const std::uint64_t r = std::uniform_int_distribution<std::uint64_t>(0, j)(rng);
        if (!ranks.insert(r).second) ranks.insert(j);
      }
      for (std::uint64_t rank : ranks) list.push_back(lp_candidate(unrank_combination(kFunctionCount, k, rank)));
    } else if (!add_alias(item)) {
      list.push_back(explicit_candidate(item));
    }
  }

  // One entry per distinct candidate: the first occurrence, with every alias it was reached by.
  std::vector<Candidate> unique;
  std::map<std::pair<Technique, std::vector<int>>, std::size_t> seen;
  for (Candidate& c : list) {
    const auto key = std::make_pair(c.technique, c.functions);
    const auto it = seen.find(key);
    if (it == seen.end()) {
      seen.emplace(key, unique.size());
      unique.push_back(std::move(c));
    } else {
      unique[it->second].listed = unique[it->second].listed || c.listed;
      for (std::string& alias : c.aliases)
        if (!unique[it->second].has_alias(alias)) unique[it->second].aliases.push_back(std::move(alias));
    }
  }
  return unique;
}

} // namespace msm::evaluate
