#include "msm/image/io.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <set>

#include <fcntl.h>
#include <unistd.h>

#include <fmt/core.h>

#include "exr_names.h"
#include "msm/util/limits.h"

#include <OpenEXR/Iex.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <cstdlib>

#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringVectorAttribute.h>

// stb's PNG reader and writer, compiled here with internal linkage (io.cpp is their only user):
// msm_image then neither needs Debian's libstb nor clashes with a downstream copy of stb.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
// stb's own deflate was 10% of a one-shot msm render at 1920x1080. libdeflate's level 1 deflates
// the Up-filtered rows of that render in 126 M instructions into 131 kB, where zlib's level 1 with
// Z_RLE (matches at distance 1 only) took 157 M for 155 kB (PNG is lossless: only the file's size
// and the time change).
#include <libdeflate.h>
namespace {
unsigned char* msm_png_deflate(unsigned char* data, int length, int* out_length, int /*quality*/) {
  libdeflate_compressor* c = libdeflate_alloc_compressor(1);
  if (!c) return nullptr;
  const std::size_t bound = libdeflate_zlib_compress_bound(c, std::size_t(length));
  auto* out = static_cast<unsigned char*>(std::malloc(bound));
  const std::size_t size = out ? libdeflate_zlib_compress(c, data, std::size_t(length), out, bound) : 0;
  libdeflate_free_compressor(c);
  if (size == 0) {
    std::free(out);
    return nullptr;
  }
  *out_length = int(size);
  return out;
}
} // namespace
#define STBIW_ZLIB_COMPRESS msm_png_deflate
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace {
// stb tries all five PNG row filters on every row and keeps the best. One filter for every row:
// Up (the row above subtracted) costs a sixth of Paeth's instructions (37 M against 206 M for a
// 1920x1080 RGB render) and, deflated with Z_RLE, gives a smaller file than Paeth with the default
// strategy did. Set once, before any thread writes.
[[maybe_unused]] const bool kUpOnly = (stbi_write_force_png_filter = 2, true);
} // namespace

namespace msm::image {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int err) { return std::strerror(err); }

std::vector<std::uint8_t> read_file(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw ImageError(path, "is a directory");
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw ImageError(path, "cannot open: " + errno_text(errno));
  std::vector<std::uint8_t> bytes;
  std::uint8_t buffer[1 << 16];
  for (;;) {
    ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      int err = errno;
      ::close(fd);
      throw ImageError(path, "cannot read: " + errno_text(err));
    }
    if (n == 0) break;
    bytes.insert(bytes.end(), buffer, buffer + n);
  }
  ::close(fd);
  return bytes;
}

void check_size(const fs::path& path, long long width, long long height) {
  if (width < 1 || height < 1 || width > max_side || height > max_side)
    throw ImageError(path, fmt::format("image size {}x{} is outside 1..{} per side", width, height, max_side));
}

// The float image's bytes against msm/util/limits.h (MSM_MAX_MEMORY_MB): a small file claiming a
// huge size is refused before the allocation.
void check_memory(const fs::path& path, long long width, long long height, long long channels) {
  try {
    limits::check_bytes(fmt::format("a {}x{} image of {} channels", width, height, channels),
                        std::uint64_t(width) * std::uint64_t(height) * std::uint64_t(channels) * sizeof(float));
  } catch (const limits::LimitError& e) { throw ImageError(path, e.what()); }
}

// Scan lines per chunk of each compression (OpenEXR's order: none, RLE, ZIPS, ZIP, PIZ, PXR24,
// B44, B44A, DWAA, DWAB); an unknown one counts as the most (OpenEXR refuses it anyway).
std::uint64_t exr_lines_per_chunk(std::uint8_t compression) {
  static constexpr std::uint16_t lines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  return compression < 10 ? lines[compression] : 256;
}

// Chunks (scan-line blocks or tiles, over all levels of a tiled file) that a header's data window
// and tile description make, or 0 where they do not say (OpenEXR then refuses the header itself).
std::uint64_t exr_chunk_count(const std::optional<std::array<std::int32_t, 4>>& window,
                              const std::optional<std::array<std::uint32_t, 2>>& tile, std::uint8_t tile_mode,
                              std::uint8_t compression) {
  if (!window) return 0;
  const std::int64_t w = std::int64_t((*window)[2]) - (*window)[0] + 1,
                     h = std::int64_t((*window)[3]) - (*window)[1] + 1;
  if (w < 1 || h < 1) return 0;
  if (!tile) {
    const std::uint64_t per_chunk = exr_lines_per_chunk(compression);
    return (std::uint64_t(h) + per_chunk - 1) / per_chunk;
  }
  const std::uint64_t tx = (*tile)[0], ty = (*tile)[1];
  if (tx == 0 || ty == 0) return 0;
  const bool round_up = (tile_mode >> 4) == 1;
  auto level_size = [&](std::int64_t size, int level) {
    const std::int64_t scaled = round_up ? (size + (std::int64_t(1) << level) - 1) >> level : size >> level;
    return std::max<std::int64_t>(scaled, 1);
  };
  auto level_count = [&](std::int64_t size) {
    int levels = 1;
    while (level_size(size, levels - 1) > 1) ++levels;
    return levels;
  };
  auto tiles = [](std::int64_t size, std::uint64_t tile_size) {
    return (std::uint64_t(size) + tile_size - 1) / tile_size;
  };
  // Saturating: 2^32 tiles a side (a data window of 2^32 pixels, 1x1 tiles) overflow 64 bits.
  auto times = [](std::uint64_t a, std::uint64_t b) { return b != 0 && a > UINT64_MAX / b ? UINT64_MAX : a * b; };
  auto plus = [](std::uint64_t a, std::uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; };
  switch (tile_mode & 0x0f) {
  case 0: return times(tiles(w, tx), tiles(h, ty)); // one level
  case 1: {                                         // mip-map: levels of both sides together
    std::uint64_t n = 0;
    for (int l = 0, levels = level_count(std::max(w, h)); l < levels; ++l)
      n = plus(n, times(tiles(level_size(w, l), tx), tiles(level_size(h, l), ty)));
    return n;
  }
  case 2: { // rip-map: every pair of an x level and a y level
    std::uint64_t nx = 0, ny = 0;
    for (int l = 0, levels = level_count(w); l < levels; ++l) nx += tiles(level_size(w, l), tx);
    for (int l = 0, levels = level_count(h); l < levels; ++l) ny += tiles(level_size(h, l), ty);
    return times(nx, ny);
  }
  default: return 0;
  }
}

// The attributes of an EXR header (each: name, type, 32-bit size, value) before OpenEXR reads
// them: OpenEXR 3.1 allocates an attribute's claimed size before reading it (gigabytes for a
// corrupt size field in a file of a kilobyte), and sizes its line and tile buffers by the data
// window, the tile size and the channels before it reads a pixel. Those are checked here first:
// the side, the channel count, one chunk's bytes against the memory limit, and the chunk count
// (scan-line blocks or tiles over all levels): a real file stores 8 bytes of offset per chunk, so
// a header implying more chunks than its file has room for is refused. (CI's image fuzzer once
// reported a 2.86 GB allocation whose input was not kept; these bound what a header can claim.)
void check_exr_header(const fs::path& path, std::span<const std::uint8_t> b) {
  std::size_t p = 8; // magic and version
  auto string_at = [&](std::size_t& at) {
    const auto end = std::find(b.begin() + std::ptrdiff_t(std::min(at, b.size())), b.end(), std::uint8_t(0));
    if (end == b.end()) throw ImageError(path, "malformed or truncated EXR: header cut short");
    std::string text(b.begin() + std::ptrdiff_t(at), end);
    at = std::size_t(end - b.begin()) + 1;
    return text;
  };
  auto u32_at = [&](std::size_t at) {
    return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 |
           std::uint32_t(b[at + 3]) << 24;
  };
  const bool multipart = b.size() > 5 && (b[5] & 0x10) != 0;
  const bool single_part_tiled = b.size() > 5 && (b[5] & 0x02) != 0;
  std::uint64_t chunks = 0;
  for (;;) {
    std::optional<std::array<std::int32_t, 4>> window;
    std::optional<std::array<std::uint32_t, 2>> tile;
    std::uint8_t tile_mode = 0, compression = 0;
    std::uint64_t chunk_count = 0; // a part's own claim (OpenEXR sizes its table by it)
    std::uint64_t channel_count = 0, pixel_bytes = 0;
    for (;;) {
      const std::string name = string_at(p);
      if (name.empty()) break;
      const std::string type = string_at(p);
      if (b.size() - p < 4) throw ImageError(path, "malformed or truncated EXR: header cut short");
      const std::int64_t size = std::int32_t(u32_at(p));
      p += 4;
      if (size < 0 || std::uint64_t(size) > b.size() - p)
        throw ImageError(path, fmt::format("malformed or truncated EXR: attribute '{}' claims {} bytes, {} are left",
                                           name, size, b.size() - p));
      if (name == "dataWindow" && type == "box2i" && size == 16)
        window = {std::int32_t(u32_at(p)), std::int32_t(u32_at(p + 4)), std::int32_t(u32_at(p + 8)),
                  std::int32_t(u32_at(p + 12))};
      if (name == "compression" && type == "compression" && size == 1) compression = b[p];
      if (name == "chunkCount" && type == "int" && size == 4)
        chunk_count = std::uint32_t(std::int32_t(u32_at(p)) < 0 ? 0 : u32_at(p));
      if (name == "channels" && type == "chlist") {
        // name, pixel type (int32: UINT, HALF, FLOAT), pLinear, 3 reserved, x and y sampling.
        for (std::size_t c = p, end = p + std::size_t(size); c < end && b[c] != 0;) {
          const auto name_end = std::find(b.begin() + std::ptrdiff_t(c), b.begin() + std::ptrdiff_t(end), 0);
          c = std::size_t(name_end - b.begin()) + 1;
          if (end < 16 || c > end - 16) break; // cut short: OpenEXR says so
          ++channel_count;
          pixel_bytes += u32_at(c) == 1 ? 2 : 4;
          c += 16;
        }
      }
      if (name == "tiles" && type == "tiledesc" && size == 9) {
        tile = {u32_at(p), u32_at(p + 4)};
        tile_mode = b[p + 8];
      }
      p += std::size_t(size);
    }
    // A multi-part file's parts say themselves whether they are tiled (their "type"); a
    // single-part file says it in the version field, and OpenEXR ignores a stray "tiles" otherwise.
    if (!multipart && !single_part_tiled) tile.reset();
    if (channel_count > std::uint64_t(max_channels))
      throw ImageError(path, fmt::format("{} channels (1..{} supported)", channel_count, max_channels));
    if (window) {
      const long long w = (long long)(*window)[2] - (*window)[0] + 1, h = (long long)(*window)[3] - (*window)[1] + 1;
      check_size(path, w, h);
      // One chunk's pixels: a tile, or the scan lines of one block.
      const std::uint64_t chunk_pixels =
          tile ? std::uint64_t((*tile)[0]) * (*tile)[1] : std::uint64_t(w) * exr_lines_per_chunk(compression);
      try {
        limits::check_bytes(tile ? fmt::format("a tile of {}x{}", (*tile)[0], (*tile)[1]) : "a block of scan lines",
                            chunk_pixels * std::max<std::uint64_t>(pixel_bytes, 1));
      } catch (const limits::LimitError& e) { throw ImageError(path, e.what()); }
    }
    // Saturating at the file's size: the sum over parts cannot overflow.
    const std::uint64_t implied = std::max(chunk_count, exr_chunk_count(window, tile, tile_mode, compression));
    chunks += std::min<std::uint64_t>(implied, b.size());
    if (chunks > b.size() / 8)
      throw ImageError(path, fmt::format("malformed or truncated EXR: its {} {} chunks, whose offset table alone "
                                         "needs more than the file's {} bytes",
                                         multipart ? "headers imply" : "header implies", implied, b.size()));
    // A multi-part file: headers until an empty one.
    if (!multipart || (p < b.size() && b[p] == 0)) break;
  }
}

bool is_png(std::span<const std::uint8_t> b) {
  static constexpr std::uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return b.size() >= 8 && std::equal(sig, sig + 8, b.begin());
}
bool is_exr(std::span<const std::uint8_t> b) {
  return b.size() >= 4 && b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01;
}

// ---- EXR streams in memory -------------------------------------------------------------------

class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(std::span<const std::uint8_t> bytes, const std::string& name)
      : Imf::IStream(name.c_str()), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (n < 0 || pos_ > bytes_.size() || bytes_.size() - pos_ < std::size_t(n))
      throw IEX_NAMESPACE::InputExc("unexpected end of file");
    std::memcpy(c, bytes_.data() + pos_, std::size_t(n));
    pos_ += std::size_t(n);
    return pos_ < bytes_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = pos; }
  void clear() override {}

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

// ---- PNG -------------------------------------------------------------------------------------

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  auto* p = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), p, p + size);
}

// stb 2.27 copies an empty IDAT chunk that comes before any image data from a null buffer
// (memcpy(NULL, p, 0): undefined behaviour, a UBSan report; a fuzzer find, tests/fuzz/crashes/
// image). An empty IDAT chunk carries nothing: the chunks are copied without them (only when there
// is one) before stb sees the file. A chunk structure that does not fit is left to stb.
std::vector<std::uint8_t> without_empty_idat(std::span<const std::uint8_t> b) {
  std::vector<std::uint8_t> out;
  bool found = false;
  std::size_t p = 8, copied = 0;
  while (b.size() - p >= 12) {
    const std::size_t length =
        std::size_t(b[p]) << 24 | std::size_t(b[p + 1]) << 16 | std::size_t(b[p + 2]) << 8 | std::size_t(b[p + 3]);
    if (length > b.size() - p - 12) break;
    if (length == 0 && std::equal(b.begin() + std::ptrdiff_t(p + 4), b.begin() + std::ptrdiff_t(p + 8), "IDAT")) {
      found = true;
      out.insert(out.end(), b.begin() + std::ptrdiff_t(copied), b.begin() + std::ptrdiff_t(p));
      copied = p + 12;
    }
    p += 12 + length;
  }
  if (!found) return {};
  out.insert(out.end(), b.begin() + std::ptrdiff_t(copied), b.end());
  return out;
}

Image decode_png(const fs::path& path, std::span<const std::uint8_t> bytes) {
  const std::vector<std::uint8_t> cleaned = without_empty_idat(bytes);
  if (!cleaned.empty()) bytes = cleaned;
  if (bytes.size() > std::size_t(INT32_MAX)) throw ImageError(path, "file too large");
  const int len = static_cast<int>(bytes.size());
  int w = 0, h = 0, n = 0;
  if (!stbi_info_from_memory(bytes.data(), len, &w, &h, &n))
    throw ImageError(path, std::string("not a readable PNG: ") + stbi_failure_reason());
  check_size(path, w, h);
  if (n < 1 || n > 4) throw ImageError(path, fmt::format("{} channels", n));
  check_memory(path, w, h, n);
  const bool sixteen = stbi_is_16_bit_from_memory(bytes.data(), len) != 0;
  const int alpha = (n == 2 || n == 4) ? n - 1 : -1;
  // Decoded before the float image is allocated: a truncated file claiming a large size fails in
  // stb first, without a zero-filled buffer of its claimed size.
  auto convert = [&](auto* data, double max) {
    if (!data) throw ImageError(path, std::string("malformed or truncated PNG: ") + stbi_failure_reason());
    const std::unique_ptr<void, void (*)(void*)> owner(data, stbi_image_free);
    Image image(w, h, n);
    auto px = image.pixels();
    for (std::size_t i = 0; i < px.size(); ++i) {
      float v = static_cast<float>(double(data[i]) / max);
      if (int(i % std::size_t(n)) == alpha)
        px[i] = v;
      else if constexpr (sizeof(*data) == 1)
        px[i] = srgb8_to_linear(data[i]); // the same value from a table
      else
        px[i] = srgb_to_linear(v);
    }
    return image;
  };
  int rw = 0, rh = 0, rn = 0;
  if (sixteen) return convert(stbi_load_16_from_memory(bytes.data(), len, &rw, &rh, &rn, n), 65535.0);
  return convert(stbi_load_from_memory(bytes.data(), len, &rw, &rh, &rn, n), 255.0);
}

// ---- EXR -------------------------------------------------------------------------------------

Image decode_exr(const fs::path& path, std::span<const std::uint8_t> bytes) {
  try {
    check_exr_header(path, bytes);
    MemoryIStream stream(bytes, path.string());
    Imf::InputFile file(stream);
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
    check_size(path, w, h);
    std::vector<std::string> names;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      const Imf::Channel& ch = it.channel();
      if (ch.xSampling != 1 || ch.ySampling != 1)
        throw ImageError(path, fmt::format("channel '{}' is subsampled (unsupported)", it.name()));
      names.emplace_back(it.name());
    }
    if (names.empty() || names.size() > std::size_t(max_channels))
      throw ImageError(path, fmt::format("{} channels (1..{} supported)", names.size(), max_channels));
    // Order: the attribute we write, else R,G,B,A / Y,A, else the file's order.
    std::set<std::string> have(names.begin(), names.end());
    std::vector<std::string> order;
    if (auto* attr = header.findTypedAttribute<Imf::StringVectorAttribute>(channel_order_attribute)) {
      const auto& v = attr->value();
      if (std::set<std::string>(v.begin(), v.end()) == have && v.size() == have.size()) order = v;
    }
    if (order.empty()) {
      for (const auto& known : {std::vector<std::string>{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}})
        if (std::set<std::string>(known.begin(), known.end()) == have) order = known;
    }
    if (order.empty()) order = names;
    check_memory(path, w, h, (long long)order.size());
    Image image(int(w), int(h), order);
    if (!file.isComplete()) throw ImageError(path, "truncated EXR (missing pixel data)");
    const std::size_t n = order.size();
    float* base = image.pixels().data();
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < n; ++c)
      fb.insert(order[c],
                Imf::Slice::Make(Imf::FLOAT, base + c, dw, sizeof(float) * n, sizeof(float) * n * std::size_t(w)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return image;
  } catch (const ImageError&) { throw; } catch (const std::exception& e) {
    throw ImageError(path, std::string("malformed or truncated EXR: ") + e.what());
  }
}

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  return ext;
}

void require_image(const fs::path& path, const Image& image) {
  if (image.empty()) throw ImageError(path, "cannot write an empty image");
}

} // namespace

// ---- Atomic write ----------------------------------------------------------------------------

namespace {

// Writes bytes to a fresh temporary file next to path, flushed to disk; returns its name. On
// failure the temporary file is removed and ImageError names path.
fs::path write_temporary(const fs::path& path, std::span<const std::uint8_t> bytes) {
  if (path.empty() || !path.has_filename()) throw ImageError(path, "not a file path");
  static std::atomic<unsigned> counter{0};
  const fs::path dir = path.parent_path();
  fs::path tmp = (dir.empty() ? fs::path(".") : dir) /
                 fmt::format(".{}.tmp.{}.{}", path.filename().string(), ::getpid(), counter++);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw ImageError(path, "cannot create temporary file " + tmp.string() + ": " + errno_text(errno));
  auto fail = [&](const std::string& what, int err) {
    if (fd >= 0) ::close(fd);
    ::unlink(tmp.c_str());
    throw ImageError(path, what + ": " + errno_text(err));
  };
  std::size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot write", errno);
    }
    done += std::size_t(n);
  }
  if (::fsync(fd) != 0) fail("cannot flush", errno);
  int rc = ::close(fd);
  fd = -1;
  if (rc != 0) fail("cannot close", errno);
  return tmp;
}

} // namespace

void write_file_atomic(const fs::path& path, std::span<const std::uint8_t> bytes) {
  const fs::path tmp = write_temporary(path, bytes);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw ImageError(path, "cannot rename the temporary file over the target: " + errno_text(err));
  }
}

// ---- File sets -------------------------------------------------------------------------------

FileSet::~FileSet() {
  for (const Pending& p : pending_)
    if (!p.tmp.empty()) ::unlink(p.tmp.c_str());
}

void FileSet::add(const fs::path& path, std::span<const std::uint8_t> bytes) {
  pending_.push_back({path, write_temporary(path, bytes)});
}

void FileSet::add_png(const fs::path& path, const Image& image) { add(path, encode_png(path, image)); }
void FileSet::add_exr(const fs::path& path, const Image& image) { add(path, encode_exr(path, image)); }
void FileSet::remove(const fs::path& path) { pending_.push_back({path, {}}); }

void FileSet::commit() {
  // An existing target is kept under a hard link until every rename has succeeded, so that a
  // failed rename can put the set back as it was.
  struct Done {
    fs::path target, backup;
  };
  std::vector<Done> done;
  auto roll_back = [&] {
    for (auto it = done.rbegin(); it != done.rend(); ++it) {
      if (!it->backup.empty())
        ::rename(it->backup.c_str(), it->target.c_str());
      else
        ::unlink(it->target.c_str());
    }
  };
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    Pending& p = pending_[i];
    fs::path backup = p.target;
    backup.replace_filename(fmt::format(".{}.old.{}", p.target.filename().string(), ::getpid()));
    ::unlink(backup.c_str());
    const bool existed = ::link(p.target.c_str(), backup.c_str()) == 0;
    const bool ok = p.tmp.empty() ? (::unlink(p.target.c_str()) == 0 || errno == ENOENT)
                                  : ::rename(p.tmp.c_str(), p.target.c_str()) == 0;
    if (!ok) {
      const int err = errno;
      if (existed) ::unlink(backup.c_str());
      roll_back();
      throw ImageError(p.target, (p.tmp.empty() ? "cannot remove the stale file: "
                                                : "cannot rename the temporary file over the target: ") +
                                     errno_text(err) + " (none of the set's files was written)");
    }
    p.tmp.clear();
    done.push_back({p.target, existed ? backup : fs::path()});
  }
  for (const Done& d : done)
    if (!d.backup.empty()) ::unlink(d.backup.c_str());
  pending_.clear();
}

// ---- PNG -------------------------------------------------------------------------------------

std::vector<std::uint8_t> encode_png8(const fs::path& path, int width, int height, int channels,
                                      std::span<const std::uint8_t> values) {
  if (width < 1 || height < 1 || width > max_side || height > max_side)
    throw ImageError(path, fmt::format("cannot write a {}x{} image: sides are 1..{}", width, height, max_side));
  if (channels < 1 || channels > max_channels)
    throw ImageError(path, fmt::format("cannot write {} channels: a PNG has 1..{}", channels, max_channels));
  if (values.size() != std::size_t(width) * std::size_t(height) * std::size_t(channels))
    throw ImageError(path,
                     fmt::format("{} bytes for a {}x{} image of {} channels", values.size(), width, height, channels));
  std::vector<std::uint8_t> encoded;
  // stb only reads the values (its signature predates const).
  if (!stbi_write_png_to_func(append_bytes, &encoded, width, height, channels, const_cast<std::uint8_t*>(values.data()),
                              width * channels))
    throw ImageError(path, "PNG encoding failed");
  return encoded;
}

std::vector<std::uint8_t> encode_png(const fs::path& path, const Image& image) {
  require_image(path, image);
  const int n = image.channels();
  const int alpha = (n == 2 || n == 4) ? n - 1 : -1; // by position, whatever the channel's name
  return encode_png8(path, image.width(), image.height(), n, to_srgb8(image, alpha));
}

void write_png(const fs::path& path, const Image& image) { write_file_atomic(path, encode_png(path, image)); }

Image read_png(const fs::path& path) {
  auto bytes = read_file(path);
  if (!is_png(bytes)) throw ImageError(path, "not a PNG file (bad signature)");
  return decode_png(path, bytes);
}

// ---- EXR -------------------------------------------------------------------------------------

// encode_exr: exr_encode.cpp.

void write_exr(const fs::path& path, const Image& image) { write_file_atomic(path, encode_exr(path, image)); }

Image read_exr(const fs::path& path) {
  auto bytes = read_file(path);
  if (!is_exr(bytes)) throw ImageError(path, "not an EXR file (bad signature)");
  return decode_exr(path, bytes);
}

Image read_image(const fs::path& path) { return decode_image(read_file(path), path); }

std::string_view to_string(FileFormat format) { return format == FileFormat::png ? "PNG" : "EXR"; }

ImageFile read_image_file(const fs::path& path) {
  const std::vector<std::uint8_t> bytes = read_file(path);
  const FileFormat format = is_png(bytes) ? FileFormat::png : FileFormat::exr;
  return {decode_image(bytes, path), format};
}

Image decode_image(std::span<const std::uint8_t> bytes, const fs::path& name) {
  if (is_png(bytes)) return decode_png(name, bytes);
  if (is_exr(bytes)) return decode_exr(name, bytes);
  throw ImageError(name, bytes.empty() ? "empty file" : "neither a PNG nor an EXR file");
}

void write_image(const fs::path& path, const Image& image) {
  const std::string ext = lower_extension(path);
  if (ext == ".png") return write_png(path, image);
  if (ext == ".exr") return write_exr(path, image);
  throw ImageError(path, "unknown image extension '" + ext + "' (.png or .exr)");
}

} // namespace msm::image
