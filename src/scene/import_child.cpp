// import_model: Assimp runs in a child process (POSIX fork), so that a crash, an abort, a sanitizer
// report, a runaway allocation or an endless loop inside Assimp ends the child, not msm, and
// becomes a SceneError naming the file. No check before Assimp can cover every bug of the library
// (docs/results.md "Fuzzing and sanitizers in CI": a heap corruption inside Assimp's OBJ loader).
//
// The child runs the import and the conversion to parts (embedded textures decoded), writes the
// parts (or its SceneError) into a pipe and leaves with _exit: no atexit handlers, no flushing of
// the parent's stdio buffers, no destructors of the parent's objects; a process that may hold
// Vulkan, Embree or TBB threads forks only this one thread, and the child touches nothing of
// theirs. The parent reads with a cap (limits::max_bytes(), MSM_MAX_MEMORY_MB), waits with a
// timeout (MSM_IMPORT_TIMEOUT_S), kills the child past it, and checks every count and size of the
// bytes it reads.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include "internal.h"
#include "msm/util/limits.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define MSM_IMPORT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define MSM_IMPORT_SANITIZED 1
#endif
#endif
#ifdef MSM_IMPORT_SANITIZED
#include <sanitizer/common_interface_defs.h>
#endif

namespace msm::scene::detail {

// 600 s: Assimp reads a 1,000,000-triangle OBJ in 3.5 s of CPU (10.2 s of wall time on the 2-core
// test machine under the load of parallel work; a binary PLY: 1.3 s, 3.8 s), so a file at the
// triangle limit (32 M, MSM_MAX_TRIANGLES) takes about 110 s of CPU, 330 s at that load
// (docs/results.md "Mesh import in a child process"); an endless loop or a deadlock in the child
// still ends, in 10 minutes.
inline constexpr double kImportTimeoutSeconds = 600.0;

void (*import_child_hook)() = nullptr;

double import_timeout_seconds() {
  return double(limits::from_environment("MSM_IMPORT_TIMEOUT_S", std::uint64_t(kImportTimeoutSeconds)));
}

namespace {

namespace fs = std::filesystem;

// The wire format: a magic, a kind, the payload, an end mark. Native byte order and float layout:
// the parent and the child are the same executable.
constexpr char kMagic[8] = {'M', 'S', 'M', 'I', 'M', 'P', '0', '1'};
constexpr char kEnd[4] = {'E', 'N', 'D', '.'};
enum Kind : std::uint8_t { kParts = 1, kSceneError = 2 };
constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();

class Writer {
 public:
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_standard_layout_v<T>); // plain numbers and glm vectors of them
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void string(const std::string& s) {
    pod(std::uint64_t(s.size()));
    out.append(s);
  }
  template <class T>
  void array(const std::vector<T>& v) {
    static_assert(std::is_standard_layout_v<T>);
    pod(std::uint64_t(v.size()));
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string out;
};

class Reader {
 public:
  Reader(std::string_view bytes, const fs::path& file) : bytes_(bytes), file_(file) {}
  [[noreturn]] void fail(const std::string& what) const {
    throw SceneError(
        file_.string(), "",
        fmt::format("the import process sent an inconsistent result ({} at byte {} of {})", what, at_, bytes_.size()));
  }
  const char* take(std::uint64_t n, const char* what) {
    if (n > bytes_.size() - at_) fail(fmt::format("{} past the end", what));
    const char* p = bytes_.data() + at_;
    at_ += std::size_t(n);
    return p;
  }
  template <class T>
  T pod(const char* what) {
    T v{};
    std::memcpy(static_cast<void*>(&v), take(sizeof(T), what), sizeof(T));
    return v;
  }
  // A count of elements of `size` bytes each that the remaining bytes can hold.
  std::uint64_t count(std::uint64_t size, const char* what) {
    const auto n = pod<std::uint64_t>(what);
    if (n > (bytes_.size() - at_) / size) fail(fmt::format("{} count {} past the end", what, n));
    return n;
  }
  std::string string(const char* what) {
    const std::uint64_t n = count(1, what);
    return std::string(take(n, what), std::size_t(n));
  }
  template <class T>
  std::vector<T> array(std::uint64_t n, const char* what) {
    std::vector<T> v(static_cast<std::size_t>(n));
    const char* from = take(n * sizeof(T), what);
    // An empty vector's data() may be null, which memcpy may not be given even for zero bytes (UBSan).
    if (n > 0) std::memcpy(static_cast<void*>(v.data()), from, std::size_t(n) * sizeof(T));
    return v;
  }
  bool at_end() const { return at_ == bytes_.size(); }

 private:
  std::string_view bytes_;
  const fs::path& file_;
  std::size_t at_ = 0;
};

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool unit_range(float v) { return v >= 0.0f && v <= 1.0f; }
bool unit_range(const glm::vec3& v) { return unit_range(v.x) && unit_range(v.y) && unit_range(v.z); }

} // namespace

std::string serialize_model(const std::vector<ModelPart>& parts) {
  Writer w;
  w.out.append(kMagic, sizeof kMagic);
  w.pod(std::uint8_t(kParts));
  // The embedded images, each once (materials share them as the importer decoded them).
  std::map<const Image*, std::uint64_t> index;
  std::vector<const Image*> images;
  auto image_index = [&](const std::shared_ptr<const Image>& image) {
    if (!image) return kNone;
    const auto [it, inserted] = index.try_emplace(image.get(), images.size());
    if (inserted) images.push_back(image.get());
    return it->second;
  };
  for (const ModelPart& part : parts)
    if (part.material) {
      image_index(part.material->albedo_pixels);
      image_index(part.material->opacity_pixels);
    }
  w.pod(std::uint64_t(images.size()));
  for (const Image* image : images) {
    w.pod(std::int32_t(image->width));
    w.pod(std::int32_t(image->height));
    w.array(image->rgba);
  }
  w.pod(std::uint64_t(parts.size()));
  for (const ModelPart& part : parts) {
    w.string(part.name);
    const Mesh& m = part.mesh;
    w.array(m.positions);
    w.array(m.normals);
    w.array(m.uvs);
    w.array(m.indices);
    w.pod(std::uint8_t(part.material.has_value()));
    if (!part.material) continue;
    const Material& mat = *part.material;
    w.string(mat.name);
    w.pod(mat.albedo);
    w.string(mat.albedo_texture.string());
    w.pod(image_index(mat.albedo_pixels));
    w.pod(mat.opacity);
    w.string(mat.opacity_texture.string());
    w.pod(image_index(mat.opacity_pixels));
    w.pod(std::uint8_t(mat.opacity_from_alpha));
    w.pod(std::uint8_t(mat.alpha_cutoff.has_value()));
    w.pod(mat.alpha_cutoff.value_or(0.0f));
    w.pod(std::uint8_t(mat.double_sided));
    w.pod(mat.transmission_color);
  }
  w.out.append(kEnd, sizeof kEnd);
  return std::move(w.out);
}

std::string serialize_error(const SceneError& error) {
  Writer w;
  w.out.append(kMagic, sizeof kMagic);
  w.pod(std::uint8_t(kSceneError));
  w.string(error.file());
  w.string(error.where());
  w.string(error.problem());
  w.out.append(kEnd, sizeof kEnd);
  return std::move(w.out);
}

std::vector<ModelPart> deserialize_model(std::string_view bytes, const fs::path& file) {
  Reader r(bytes, file);
  if (std::memcmp(r.take(sizeof kMagic, "the header"), kMagic, sizeof kMagic) != 0) r.fail("no header");
  const auto kind = r.pod<std::uint8_t>("the kind");
  std::vector<ModelPart> parts;
  if (kind == kSceneError) {
    std::string error_file = r.string("the error's file");
    std::string where = r.string("the error's place");
    std::string problem = r.string("the error");
    if (std::memcmp(r.take(sizeof kEnd, "the end mark"), kEnd, sizeof kEnd) != 0 || !r.at_end()) r.fail("no end mark");
    throw SceneError(std::move(error_file), std::move(where), std::move(problem));
  }
  if (kind != kParts) r.fail(fmt::format("unknown kind {}", kind));
  const std::uint64_t image_count = r.count(8 + 8, "image");
  std::vector<std::shared_ptr<const Image>> images;
  for (std::uint64_t i = 0; i < image_count; ++i) {
    auto image = std::make_shared<Image>();
    image->width = r.pod<std::int32_t>("an image's width");
    image->height = r.pod<std::int32_t>("an image's height");
    const std::uint64_t texels = r.count(1, "texel byte");
    if (image->width < 0 || image->height < 0 ||
        texels != 4 * std::uint64_t(image->width) * std::uint64_t(image->height))
      r.fail(fmt::format("an image of {}x{} with {} bytes", image->width, image->height, texels));
    image->rgba = r.array<std::uint8_t>(texels, "texels");
    images.push_back(std::move(image));
  }
  auto image_at = [&](std::uint64_t i) -> std::shared_ptr<const Image> {
    if (i == kNone) return nullptr;
    if (i >= images.size()) r.fail(fmt::format("image {} of {}", i, images.size()));
    return images[std::size_t(i)];
  };
  const std::uint64_t part_count = r.count(8 * 5 + 1, "part");
  for (std::uint64_t p = 0; p < part_count; ++p) {
    ModelPart part;
    part.name = r.string("a part's name");
    Mesh& m = part.mesh;
    const std::uint64_t vertices = r.count(sizeof(glm::vec3), "position");
    m.positions = r.array<glm::vec3>(vertices, "positions");
    if (r.count(sizeof(glm::vec3), "normal") != vertices) r.fail("normals not one per position");
    m.normals = r.array<glm::vec3>(vertices, "normals");
    if (r.count(sizeof(glm::vec2), "texture coordinate") != vertices) r.fail("uvs not one per position");
    m.uvs = r.array<glm::vec2>(vertices, "uvs");
    const std::uint64_t indices = r.count(sizeof(std::uint32_t), "index");
    if (indices == 0 || indices % 3 != 0) r.fail(fmt::format("{} indices", indices));
    m.indices = r.array<std::uint32_t>(indices, "indices");
    for (const glm::vec3& v : m.positions)
      if (!finite(v)) r.fail("a non-finite position");
    for (std::uint32_t i : m.indices)
      if (i >= vertices) r.fail(fmt::format("index {} of {} vertices", i, vertices));
    const auto has_material = r.pod<std::uint8_t>("the material flag");
    if (has_material > 1) r.fail("the material flag");
    if (has_material) {
      Material& mat = part.material.emplace();
      mat.name = r.string("a material's name");
      mat.albedo = r.pod<glm::vec3>("the albedo");
      mat.albedo_texture = r.string("the albedo texture");
      mat.albedo_pixels = image_at(r.pod<std::uint64_t>("the albedo image"));
      mat.opacity = r.pod<float>("the opacity");
      mat.opacity_texture = r.string("the opacity texture");
      mat.opacity_pixels = image_at(r.pod<std::uint64_t>("the opacity image"));
      const auto from_alpha = r.pod<std::uint8_t>("opacity_from_alpha");
      const auto has_cutoff = r.pod<std::uint8_t>("the cutoff flag");
      const auto cutoff = r.pod<float>("the cutoff");
      const auto double_sided = r.pod<std::uint8_t>("double_sided");
      mat.transmission_color = r.pod<glm::vec3>("the transmission colour");
      if (from_alpha > 1 || has_cutoff > 1 || double_sided > 1) r.fail("a material's flag");
      if (!unit_range(mat.albedo) || !unit_range(mat.opacity) || !unit_range(cutoff) ||
          !unit_range(mat.transmission_color))
        r.fail("a material's value outside [0, 1]");
      mat.opacity_from_alpha = from_alpha != 0;
      if (has_cutoff) mat.alpha_cutoff = cutoff;
      mat.double_sided = double_sided != 0;
    }
    parts.push_back(std::move(part));
  }
  if (parts.empty()) r.fail("no parts");
  if (std::memcmp(r.take(sizeof kEnd, "the end mark"), kEnd, sizeof kEnd) != 0 || !r.at_end()) r.fail("no end mark");
  return parts;
}

namespace {

bool write_all(int fd, const std::string& bytes) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + at, bytes.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    at += std::size_t(n);
  }
  return true;
}

// The child: only the import, its allocations, the pipe and _exit.
[[noreturn]] void child_main(const fs::path& file, int result_fd, int error_fd, rlim_t address_space) {
  // The parent's handlers (an application's, libFuzzer's) are not the child's: a crash ends it
  // with its signal, which the parent reports; no core file.
  for (int sig = 1; sig < NSIG; ++sig)
    if (sig != SIGKILL && sig != SIGSTOP) ::signal(sig, SIG_DFL);
  sigset_t all;
  sigemptyset(&all);
  ::sigprocmask(SIG_SETMASK, &all, nullptr);
#ifdef MSM_IMPORT_SANITIZED
  // A sanitizer report ends the child (exit status 1) without the parent's death callback
  // (libFuzzer's would save the input as a crash of the parent's).
  __sanitizer_set_death_callback(nullptr);
#endif
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  // A runaway allocation inside Assimp ends in std::bad_alloc. Not under sanitizers: they
  // reserve terabytes of address space for their shadow memory.
  if (address_space != 0) {
    const rlimit as{address_space, address_space};
    ::setrlimit(RLIMIT_AS, &as);
  }
  // Whatever the child prints (an abort's or a sanitizer's message) goes to the parent, which
  // quotes it; nothing reaches the parent's stdout. The result pipe becomes fd 3, every other
  // inherited descriptor is closed.
  const int result = ::fcntl(result_fd, F_DUPFD, 10), error = ::fcntl(error_fd, F_DUPFD, 10);
  if (result < 0 || error < 0 || ::dup2(error, 1) < 0 || ::dup2(error, 2) < 0 || ::dup2(result, 3) < 0) ::_exit(120);
  ::close_range(4, ~0u, 0);
  std::string bytes;
  try {
    if (import_child_hook) import_child_hook();
    bytes = serialize_model(import_model_in_process(file));
  } catch (const SceneError& e) { bytes = serialize_error(e); } catch (const std::bad_alloc&) {
    bytes = serialize_error(SceneError(
        file.string(), "",
        fmt::format("Assimp ran out of memory reading the mesh (the limit is {} MiB: MSM_MAX_MEMORY_MB raises it)",
                    limits::max_bytes() >> 20)));
  } catch (const std::exception& e) {
    bytes = serialize_error(SceneError(file.string(), "", fmt::format("Assimp cannot read the mesh: {}", e.what())));
  } catch (...) {
    bytes = serialize_error(SceneError(file.string(), "", "Assimp cannot read the mesh: an unknown exception"));
  }
  ::_exit(write_all(3, bytes) ? 0 : 121);
}

// The address space the child may use: this process's own (what it inherits) plus the memory
// limit; 0 = no limit (sanitizers, or /proc unreadable).
rlim_t child_address_space() {
#ifdef MSM_IMPORT_SANITIZED
  return 0;
#else
  const int fd = ::open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  char text[128] = {};
  const ssize_t n = ::read(fd, text, sizeof text - 1);
  ::close(fd);
  if (n <= 0) return 0;
  const unsigned long long pages = std::strtoull(text, nullptr, 10);
  if (pages == 0) return 0;
  return rlim_t(pages * std::uint64_t(::sysconf(_SC_PAGESIZE)) + limits::max_bytes());
#endif
}

struct Pipe {
  int fd[2] = {-1, -1};
  Pipe() {
    if (::pipe2(fd, O_CLOEXEC) != 0) throw std::system_error(errno, std::generic_category(), "pipe2");
  }
  ~Pipe() {
    close(0);
    close(1);
  }
  void close(int end) {
    if (fd[end] >= 0) ::close(fd[end]);
    fd[end] = -1;
  }
};

std::string signal_name(int sig) {
  const char* description = ::sigdescr_np(sig);
  return description ? fmt::format("signal {}, {}", sig, description) : fmt::format("signal {}", sig);
}

// The first line of what the child printed, for the message.
std::string first_line(const std::string& text) {
  std::size_t start = text.find_first_not_of(" \t\r\n");
  if (start == std::string::npos) return "";
  std::string line = text.substr(start, text.find('\n', start) - start);
  if (line.size() > 200) line = line.substr(0, 200) + "...";
  return line;
}

} // namespace

} // namespace msm::scene::detail

namespace msm::scene {

std::vector<ModelPart> import_model(const std::filesystem::path& file) {
  using Clock = std::chrono::steady_clock;
  detail::check_mesh_file(file);
  const double timeout = detail::import_timeout_seconds();
  const std::uint64_t cap = limits::max_bytes();
  const rlim_t address_space = detail::child_address_space();
  detail::Pipe result, error;
  const pid_t pid = ::fork();
  if (pid < 0) throw std::system_error(errno, std::generic_category(), "fork (for the mesh import)");
  if (pid == 0) detail::child_main(file, result.fd[1], error.fd[1], address_space);
  result.close(1);
  error.close(1);
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  auto fail = [&](const std::string& problem) -> SceneError {
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {}
    return SceneError(file.string(), "", problem);
  };
  auto timed_out = [&] {
    return fail(
        fmt::format("Assimp did not finish reading the mesh within {} s (MSM_IMPORT_TIMEOUT_S raises it)", timeout));
  };
  std::string bytes, printed;
  std::vector<char> buffer(1 << 16);
  while (result.fd[0] >= 0 || error.fd[0] >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) throw timed_out();
    pollfd fds[2] = {{result.fd[0], POLLIN, 0}, {error.fd[0], POLLIN, 0}};
    const int ready = ::poll(fds, 2, int(std::min<long long>(left, 1000)));
    if (ready < 0 && errno != EINTR) throw fail(fmt::format("poll: {}", std::strerror(errno)));
    if (ready <= 0) continue;
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || fds[k].revents == 0) continue;
      const ssize_t n = ::read(fds[k].fd, buffer.data(), buffer.size());
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) {
        (k == 0 ? result : error).close(0);
        continue;
      }
      if (k == 1) {
        if (printed.size() < 4096)
          printed.append(buffer.data(), std::min<std::size_t>(std::size_t(n), 4096 - printed.size()));
        continue;
      }
      if (bytes.size() + std::size_t(n) > cap)
        throw fail(
            fmt::format("the imported mesh needs more than {} MiB (MSM_MAX_MEMORY_MB raises the limit)", cap >> 20));
      bytes.append(buffer.data(), std::size_t(n));
    }
  }
  // Both pipes closed: the child has ended or is ending. Its end is awaited through a pidfd
  // (polled until the deadline), or where there is none by polling waitpid every millisecond.
  int status = 0;
  const int pidfd = int(::syscall(SYS_pidfd_open, pid, 0));
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) {
      if (pidfd >= 0) ::close(pidfd);
      throw fail(fmt::format("waitpid: {}", std::strerror(errno)));
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) {
      if (pidfd >= 0) ::close(pidfd);
      throw timed_out();
    }
    pollfd ended{pidfd, POLLIN, 0};
    if (pidfd >= 0)
      ::poll(&ended, 1, int(std::min<long long>(left, 1000)));
    else
      ::usleep(1000);
  }
  if (pidfd >= 0) ::close(pidfd);
  const std::string said = detail::first_line(printed);
  if (WIFSIGNALED(status))
    throw SceneError(file.string(), "",
                     fmt::format("Assimp crashed while reading the mesh ({}{}{})",
                                 detail::signal_name(WTERMSIG(status)), said.empty() ? "" : ": ", said));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw SceneError(file.string(), "",
                     fmt::format("Assimp crashed while reading the mesh (exit status {}{}{})", WEXITSTATUS(status),
                                 said.empty() ? "" : ": ", said));
  return detail::deserialize_model(bytes, file);
}

} // namespace msm::scene
