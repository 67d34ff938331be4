// Lists written as text ("a,b,c"): the CLI's comma lists and the evaluation's candidate specs.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace msm::util {

// The parts between separators, empty ones included: "a,,b" gives a, "", b; "" gives one empty part.
inline std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

// The non-empty parts, as strings: "a,,b," gives a, b; "" gives none.
inline std::vector<std::string> split_nonempty(std::string_view text, char separator) {
  std::vector<std::string> parts;
  for (std::string_view part : split(text, separator))
    if (!part.empty()) parts.emplace_back(part);
  return parts;
}

} // namespace msm::util
