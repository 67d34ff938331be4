// Shared by the fuzz targets (tests/fuzz/fuzz_*.cpp). Each target defines libFuzzer's two entry
// points, LLVMFuzzerInitialize and LLVMFuzzerTestOneInput; the clang build (MSM_BUILD_FUZZERS)
// links them with libFuzzer, the normal build with replay.cpp, which runs them on the committed
// corpus and crash reproducers as regression tests. A target accepts the library's documented
// error (SceneError, ImageError) and checks what a successful load must satisfy: any other
// exception, a failed check or a sanitizer report is a crash.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv);
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

// A failed check aborts: libFuzzer and the replay driver report it as a crash.
#define MSM_FUZZ_CHECK(condition)                                                                                      \
  do {                                                                                                                 \
    if (!(condition)) {                                                                                                \
      std::fprintf(stderr, "%s:%d: fuzz check failed: %s\n", __FILE__, __LINE__, #condition);                          \
      std::abort();                                                                                                    \
    }                                                                                                                  \
  } while (0)

namespace msm::fuzz {

// A directory of this process for the files a target writes, removed at a normal exit.
inline const std::filesystem::path& scratch_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      std::string pattern = (std::filesystem::temp_directory_path() / "msm-fuzz-XXXXXX").string();
      if (!::mkdtemp(pattern.data())) {
        std::perror("mkdtemp");
        std::abort();
      }
      path = pattern;
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

// An input the library refused with its documented error; printed with MSM_FUZZ_VERBOSE=1 (to
// see which seeds load).
inline void rejected(const std::exception& e) {
  if (std::getenv("MSM_FUZZ_VERBOSE")) std::fprintf(stderr, "  rejected: %s\n", e.what());
}

inline void write_bytes(const std::filesystem::path& path, const void* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), std::streamsize(size));
  out.close();
  MSM_FUZZ_CHECK(out.good());
}

// The limits of msm/util/limits.h lowered (environment, as a user would): an input that asks for
// more is refused by the code under test, quickly, instead of costing the fuzzer seconds and
// gigabytes (libFuzzer's -rss_limit_mb is 2048 by default).
inline void lower_limits() {
  ::setenv("MSM_MAX_TRIANGLES", "200000", 1);
  ::setenv("MSM_MAX_MEMORY_MB", "256", 1);
}

} // namespace msm::fuzz
