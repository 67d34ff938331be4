// The output directory of a long run, checked before the work starts: a run of minutes should not
// end in "cannot write".
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

namespace msm::util {

// Creates `dir` (and its parents) and writes and removes a small file `.<probe_name>.<pid>` there.
// The problem in words ("cannot create the directory: …", "not a directory", "the directory is not
// writable"), or nothing when files can be written there; the caller names the option.
inline std::optional<std::string> prepare_output_dir(const std::filesystem::path& dir, std::string_view probe_name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return "cannot create the directory: " + ec.message();
  if (!fs::is_directory(dir, ec)) return "not a directory";
  const fs::path probe = dir / fmt::format(".{}.{}", probe_name, ::getpid());
  bool writable = false;
  {
    std::ofstream out(probe, std::ios::binary);
    writable = out && (out << "probe") && out.flush();
  }
  fs::remove(probe, ec);
  if (!writable) return "the directory is not writable";
  return std::nullopt;
}

} // namespace msm::util
