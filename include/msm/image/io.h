// Reading and writing images: PNG (8-bit sRGB, via stb) and EXR (32-bit float, OpenEXR).
//
// Every write is atomic: the file is encoded in memory, written to a temporary file in the
// target's directory (".<name>.tmp.<pid>.<n>"), flushed to disk (fsync) and renamed over the
// target only when complete; on any failure the temporary file is removed, an existing target is
// left untouched, and ImageError (path + reason) is thrown. Reading a missing, unreadable,
// malformed or truncated file, or one with a side of 0 or > max_side, throws ImageError.
#pragma once

#include "msm/image/image.h"

#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

namespace msm::image {

// PNG with 1 (grey), 2 (grey + alpha), 3 (RGB) or 4 (RGBA) channels, 8 bits per channel: colour
// channels sRGB-encoded from linear values clamped to [0,1] (see to_srgb8), alpha linear.
// Channel names are not stored.
void write_png(const std::filesystem::path& path, const Image& image);
// Any 8- or 16-bit PNG; values decoded to linear (sRGB decode for colour channels, alpha / max),
// default channel names for the channel count.
Image read_png(const std::filesystem::path& path);

// EXR, scanline, ZIP-compressed, every channel 32-bit float (lossless), named by
// image.channel_names(). The channel order is kept in the attribute "msmChannelOrder" (EXR itself
// sorts channels by name).
void write_exr(const std::filesystem::path& path, const Image& image);
// Any scanline or tiled EXR (half, float or uint channels, converted to float) with 1..4
// channels. Order: "msmChannelOrder" when present; otherwise R,G,B,A / Y,A when the names are
// exactly such a set; otherwise the file's (alphabetical) order.
Image read_exr(const std::filesystem::path& path);

// By content (PNG or EXR signature), whatever the extension.
Image read_image(const std::filesystem::path& path);
// The encoding of an image file's values: sRGB-encoded integers (PNG, a picture for display) or
// linear floats (EXR). read_png decodes a PNG to linear values, but whatever tone curve and clamp
// made the picture stay in them.
enum class FileFormat { png, exr };
std::string_view to_string(FileFormat format);
struct ImageFile {
  Image image;
  FileFormat format;
};
// read_image and the format it found.
ImageFile read_image_file(const std::filesystem::path& path);
// The same for a file already in memory (name: for the messages only).
Image decode_image(std::span<const std::uint8_t> bytes, const std::filesystem::path& name);
// By extension: ".png" or ".exr" (case-insensitive); anything else throws ImageError.
void write_image(const std::filesystem::path& path, const Image& image);

// The atomic write used by the above, for any bytes.
void write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
// The encoded files of write_png and write_exr (path: for the messages).
std::vector<std::uint8_t> encode_png(const std::filesystem::path& path, const Image& image);
// The PNG of 8-bit values stored as they are: width x height pixels of `channels` (1..4)
// interleaved bytes, row-major, colour channels already sRGB-encoded (a renderer's R8G8B8A8_SRGB
// target read back). encode_png(image) is encode_png8 of the image's values encoded as write_png
// says, so 8-bit values decoded with srgb8_to_linear give the same file either way. ImageError for a size outside
// 1..max_side, a channel count outside 1..4 or a byte count other than width * height * channels.
std::vector<std::uint8_t> encode_png8(const std::filesystem::path& path, int width, int height, int channels,
                                      std::span<const std::uint8_t> values);
std::vector<std::uint8_t> encode_exr(const std::filesystem::path& path, const Image& image);

// Files that appear together or not at all (a render's PNG, EXR and JSON; a reference's EXRs and
// JSON): each add writes a complete temporary file next to its target (a full disk fails here,
// before any target changes), commit renames them all over their targets. A failed rename puts
// the targets renamed before it back (an overwritten file from a hard link kept until the end) and
// throws ImageError; a set destroyed without commit removes its temporary files.
class FileSet {
 public:
  FileSet() = default;
  FileSet(const FileSet&) = delete;
  FileSet& operator=(const FileSet&) = delete;
  ~FileSet();
  void add(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
  void add_png(const std::filesystem::path& path, const Image& image);
  void add_exr(const std::filesystem::path& path, const Image& image);
  // A stale file of an earlier run, removed at commit with the others' renames.
  void remove(const std::filesystem::path& path);
  void commit();

 private:
  struct Pending {
    std::filesystem::path target, tmp; // tmp empty: remove target
  };
  std::vector<Pending> pending_;
};

} // namespace msm::image
