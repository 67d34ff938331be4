// Writes the EXR seeds of the image and compare fuzz targets (tests/fuzz/corpus/{image,compare}):
// small scanline and tiled EXRs in every compression OpenEXR 3.1 writes, with half, float and
// uint channels and 1..4 channels (what decode_exr accepts) and a few it refuses. OpenEXR is not
// instrumented in the fuzz build, so libFuzzer cannot find these formats by itself.
//   g++ -std=c++20 -O1 $(pkg-config --cflags OpenEXR) make_exr_seeds.cpp $(pkg-config --libs OpenEXR)
//   ./a.out tests/fuzz/corpus/image
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <filesystem>
#include <string>
#include <vector>

namespace {

struct Seed {
  std::string name;
  Imf::Compression compression;
  Imf::PixelType type;
  std::vector<std::string> channels;
  bool tiled = false;
  int width = 5, height = 4;
};

void write(const std::filesystem::path& dir, const Seed& s) {
  Imf::Header header(s.width, s.height);
  header.compression() = s.compression;
  for (const std::string& c : s.channels) header.channels().insert(c, Imf::Channel(s.type));
  const std::size_t n = s.channels.size(), pixels = std::size_t(s.width) * std::size_t(s.height);
  std::vector<float> f(pixels * n);
  std::vector<half> h(pixels * n);
  std::vector<unsigned> u(pixels * n);
  for (std::size_t i = 0; i < f.size(); ++i) {
    f[i] = float(i % 7) / 6.0f;
    h[i] = half(f[i]);
    u[i] = unsigned(i);
  }
  char* base = s.type == Imf::FLOAT  ? reinterpret_cast<char*>(f.data())
               : s.type == Imf::HALF ? reinterpret_cast<char*>(h.data())
                                     : reinterpret_cast<char*>(u.data());
  const std::size_t size = s.type == Imf::HALF ? 2 : 4;
  Imf::FrameBuffer fb;
  for (std::size_t c = 0; c < n; ++c)
    fb.insert(s.channels[c], Imf::Slice(s.type, base + c * size, size * n, size * n * std::size_t(s.width)));
  const std::string path = (dir / s.name).string();
  if (s.tiled) {
    header.setTileDescription(Imf::TileDescription(2, 2, Imf::ONE_LEVEL));
    Imf::TiledOutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writeTiles(0, file.numXTiles() - 1, 0, file.numYTiles() - 1);
  } else {
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(s.height);
  }
}

} // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  using Imf::FLOAT, Imf::HALF, Imf::UINT;
  const std::vector<Seed> seeds = {
      {"none_float_y.exr", Imf::NO_COMPRESSION, FLOAT, {"Y"}},
      {"rle_half_ya.exr", Imf::RLE_COMPRESSION, HALF, {"Y", "A"}},
      {"zips_float_rgb.exr", Imf::ZIPS_COMPRESSION, FLOAT, {"R", "G", "B"}},
      {"zip_half_rgba.exr", Imf::ZIP_COMPRESSION, HALF, {"R", "G", "B", "A"}},
      {"piz_float_named.exr", Imf::PIZ_COMPRESSION, FLOAT, {"visibility", "sample_count", "std_error"}},
      {"pxr24_float_y.exr", Imf::PXR24_COMPRESSION, FLOAT, {"Y"}},
      {"b44_half_rgb.exr", Imf::B44_COMPRESSION, HALF, {"R", "G", "B"}},
      {"b44a_half_rgba.exr", Imf::B44A_COMPRESSION, HALF, {"R", "G", "B", "A"}},
      {"dwaa_half_rgb.exr", Imf::DWAA_COMPRESSION, HALF, {"R", "G", "B"}},
      {"dwab_float_y.exr", Imf::DWAB_COMPRESSION, FLOAT, {"Y"}},
      {"none_uint_y.exr", Imf::NO_COMPRESSION, UINT, {"Y"}},
      {"tiled_zip_float_rgb.exr", Imf::ZIP_COMPRESSION, FLOAT, {"R", "G", "B"}, true},
      {"five_channels.exr", Imf::NO_COMPRESSION, HALF, {"A", "B", "G", "R", "Z"}},
      {"one_pixel.exr", Imf::ZIP_COMPRESSION, FLOAT, {"visibility"}, false, 1, 1},
  };
  for (const Seed& s : seeds) write(dir, s);
  return 0;
}
