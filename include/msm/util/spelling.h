// Nearest names for a misspelt one (C++ only): the "did you mean" of the CLI (options, commands)
// and of the technique table. One definition of the distance, so that both suggest alike.
#pragma once

#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>
#include <vector>

namespace msm::util {

// Optimal-string-alignment distance, case-insensitive: insertions, deletions, substitutions and
// swaps of two neighbouring characters each cost 1 (a swap is the commonest typing slip).
inline int edit_distance(std::string_view a, std::string_view b) {
  auto same = [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  };
  const size_t n = a.size(), m = b.size();
  std::vector<int> d((n + 1) * (m + 1));
  auto at = [&](size_t i, size_t j) -> int& { return d[i * (m + 1) + j]; };
  for (size_t i = 0; i <= n; ++i) at(i, 0) = int(i);
  for (size_t j = 0; j <= m; ++j) at(0, j) = int(j);
  for (size_t i = 1; i <= n; ++i)
    for (size_t j = 1; j <= m; ++j) {
      int cost = same(a[i - 1], b[j - 1]) ? 0 : 1;
      at(i, j) = std::min({at(i - 1, j) + 1, at(i, j - 1) + 1, at(i - 1, j - 1) + cost});
      if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1]))
        at(i, j) = std::min(at(i, j), at(i - 2, j - 2) + 1);
    }
  return at(n, m);
}

// The candidates nearest to word, best first (at most 3): those within a distance of a third of
// the word's length (at least 1), else those it is the start of (at least 3 characters typed).
// Empty when nothing is near: a suggestion far from what was typed misleads more than none.
inline std::vector<std::string> nearest_names(std::string_view word, const std::vector<std::string>& candidates) {
  const int limit = std::max<int>(1, int(word.size()) / 3);
  std::vector<std::pair<int, std::string>> near;
  for (const std::string& c : candidates)
    if (int dist = edit_distance(word, c); dist <= limit) near.emplace_back(dist, c);
  if (near.empty() && word.size() >= 3)
    for (const std::string& c : candidates)
      if (c.size() > word.size() && edit_distance(word, std::string_view(c).substr(0, word.size())) == 0)
        near.emplace_back(int(c.size() - word.size()), c);
  std::sort(near.begin(), near.end());
  std::vector<std::string> out;
  for (size_t i = 0; i < near.size() && i < 3; ++i) out.push_back(near[i].second);
  return out;
}

// " (did you mean a, b or c?)", or "" when nothing is near.
inline std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates) {
  std::vector<std::string> near = nearest_names(word, candidates);
  if (near.empty()) return "";
  std::string s = " (did you mean " + near[0];
  for (size_t i = 1; i < near.size(); ++i) s += (i + 1 == near.size() ? " or " : ", ") + near[i];
  return s + "?)";
}

} // namespace msm::util
