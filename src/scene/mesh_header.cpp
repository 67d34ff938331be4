// What a mesh file declares, read before Assimp imports it (detail::check_mesh_header).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "internal.h"
#include "msm/util/limits.h"

namespace msm::scene::detail {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void refuse(const fs::path& file, const std::string& problem) {
  throw SceneError(file.string(), "", problem);
}

std::string read_all(const fs::path& file, std::uint64_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string text(size, '\0');
  in.read(text.data(), std::streamsize(size));
  if (!in) refuse(file, "cannot read the mesh file");
  return text;
}

std::uint64_t count_of(const fs::path& file, const std::string& token, const char* what) {
  if (token.empty() || token.size() > 19 || token.find_first_not_of("0123456789") != std::string::npos)
    refuse(file, fmt::format("the header's {} count '{}' is not a number", what, token));
  return std::stoull(token);
}

// An ASCII PLY body as the format has it: one element per line, in the header's order, each line
// exactly its properties' numbers (a list: its count, then that many), face indices within the
// vertices. Assimp 5.2 reads past its buffers on some bodies that break this (a bus error from a
// 657-byte file: a fuzzer find, tests/fuzz/crashes/mesh_import); they are refused here instead.
template <class Element>
void check_ply_ascii_body(const fs::path& file, std::uint64_t size, std::uint64_t start,
                          const std::vector<Element>& elements) {
  const std::string text = read_all(file, size);
  std::size_t at = std::size_t(std::min<std::uint64_t>(start, text.size()));
  if (at < text.size() && text[at] == '\r') ++at;
  if (at < text.size() && text[at] == '\n') ++at;
  std::uint64_t vertices = 0, line_number = 0;
  for (const Element& e : elements) {
    if (e.name == "vertex") vertices = e.count;
    for (std::uint64_t i = 0; i < e.count; ++i) {
      std::vector<std::string> tokens;
      do { // a line, blank ones skipped
        if (at >= text.size())
          refuse(file,
                 fmt::format("the PLY body ends in element '{}' ({} of {} read; truncated?)", e.name, i, e.count));
        const std::size_t eol = std::min(text.find('\n', at), text.size());
        std::istringstream words(text.substr(at, eol - at));
        tokens.clear();
        for (std::string w; words >> w;) tokens.push_back(w);
        at = eol + 1;
        ++line_number;
      } while (tokens.empty());
      auto number = [&](std::size_t k) {
        char* stop = nullptr;
        const double v = std::strtod(tokens[k].c_str(), &stop);
        // NaN and inf are numbers here: the loader names non-finite vertices itself, afterwards.
        if (*stop != '\0' || stop == tokens[k].c_str())
          refuse(file, fmt::format("line {} of the PLY body: '{}' is not a number", line_number, tokens[k]));
        return v;
      };
      std::size_t k = 0;
      for (bool list : e.lists) {
        if (k >= tokens.size()) break;
        if (!list) {
          (void)number(k++);
          continue;
        }
        const double n = number(k++);
        if (n < 0 || n != std::floor(n) || n > double(tokens.size()))
          refuse(file, fmt::format("line {} of the PLY body: a list of {} values", line_number, tokens[k - 1]));
        for (std::size_t j = 0; j < std::size_t(n) && k < tokens.size(); ++j) {
          const double v = number(k++);
          if (e.name == "face" && !(v >= 0 && v < double(vertices)))
            refuse(file, fmt::format("line {} of the PLY body: vertex index {} of {} vertices", line_number,
                                     tokens[k - 1], vertices));
        }
      }
      std::size_t expected = 0;
      {
        std::size_t j = 0;
        for (bool list : e.lists) {
          if (j >= tokens.size()) {
            expected = SIZE_MAX;
            break;
          }
          const std::size_t n = list ? std::size_t(std::strtod(tokens[j].c_str(), nullptr)) : 0;
          expected += 1 + n;
          j += 1 + n;
        }
      }
      if (expected != tokens.size())
        refuse(file, fmt::format("line {} of the PLY body has {} values; element '{}' declares {} (corrupt?)",
                                 line_number, tokens.size(), e.name,
                                 expected == SIZE_MAX ? std::string("more") : std::to_string(expected)));
    }
  }
}

// PLY: "ply", "format <ascii|binary_*> 1.0", "element <name> <count>" with its "property" lines,
// "end_header". Assimp 5.2 reads a header without end_header forever (a fuzzer's find), so a
// header must end within the first 64 KiB; the elements' smallest encoding must fit the file.
std::uint64_t ply_triangles(const fs::path& file, std::uint64_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string head(std::size_t(std::min<std::uint64_t>(size, 64 << 10)), '\0');
  in.read(head.data(), std::streamsize(head.size()));
  // end_header as a line of its own (Assimp also hangs on "end_header" followed by other bytes).
  std::size_t end = std::string::npos;
  for (std::size_t at = head.find("\nend_header"); at != std::string::npos; at = head.find("\nend_header", at + 1)) {
    const std::size_t after = at + 11;
    if (after < head.size() && (head[after] == '\n' || head.compare(after, 2, "\r\n") == 0)) {
      end = at + 1;
      break;
    }
  }
  if (end == std::string::npos)
    refuse(file, "the PLY header has no end_header line in its first 64 KiB (truncated or corrupt?)");
  std::istringstream lines(head.substr(0, end));
  std::string line;
  bool ascii = true;
  std::uint64_t faces = 0, minimum_bytes = 0, count = 0, element_bytes = 0;
  // ASCII: each element's properties in order (true: a list), for the check of the body below.
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<bool> lists;
  };
  std::vector<Element> elements;
  auto close_element = [&] {
    // Every property takes at least 2 characters in ASCII ("0 "); lists at least their count.
    minimum_bytes = std::min<std::uint64_t>(minimum_bytes + count * element_bytes, UINT64_MAX / 2);
    count = element_bytes = 0;
  };
  for (int number = 1; std::getline(lines, line); ++number) {
    std::istringstream words(line);
    std::string keyword, a, b, c;
    words >> keyword >> a >> b >> c;
    // Text only: Assimp's header parser hangs on some other bytes (fuzzer finds,
    // tests/fuzz/crashes/mesh_import). Lines of other words are left to it (Blender wrote a
    // free-text line into Wuson.ply's header, and Assimp reads the file).
    const bool text = std::all_of(line.begin(), line.end(),
                                  [](unsigned char ch) { return ch == '\t' || ch == '\r' || (ch >= 32 && ch < 127); });
    if (!text) refuse(file, fmt::format("line {} of the PLY header is not text (corrupt?)", number));
    if (keyword == "format") {
      ascii = a == "ascii";
    } else if (keyword == "element") {
      close_element();
      count = count_of(file, b, fmt::format("PLY element '{}'", a).c_str());
      if (a == "face") faces += count;
      elements.push_back({a, count, {}});
    } else if (keyword == "property") {
      static const std::pair<const char*, int> kSizes[] = {{"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},
                                                           {"short", 2}, {"ushort", 2},  {"int16", 2},  {"uint16", 2},
                                                           {"int", 4},   {"uint", 4},    {"int32", 4},  {"uint32", 4},
                                                           {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
      const std::string& type = a == "list" ? b : a; // a list: at least its count
      int bytes = 1;
      for (const auto& [name, n] : kSizes)
        if (type == name) bytes = n;
      element_bytes += ascii ? 2 : std::uint64_t(bytes);
      if (!elements.empty()) elements.back().lists.push_back(a == "list");
    }
  }
  close_element();
  const std::uint64_t body = size - std::min<std::uint64_t>(size, end + 11);
  if (minimum_bytes > body)
    refuse(file, fmt::format("the PLY header declares elements of at least {} bytes, the file has {} after its header "
                             "(truncated or corrupt?)",
                             limits::with_commas(minimum_bytes), limits::with_commas(body)));
  if (ascii) check_ply_ascii_body(file, size, end + 11, elements);
  return faces;
}

// OFF: "[ST][C][N][4]OFF", then (after comments) "vertices faces edges".
std::uint64_t off_triangles(const fs::path& file, std::uint64_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string head(std::size_t(std::min<std::uint64_t>(size, 64 << 10)), '\0');
  in.read(head.data(), std::streamsize(head.size()));
  std::istringstream lines(head);
  std::string line;
  std::vector<std::string> tokens;
  bool keyword = false;
  while (tokens.size() < 2 && std::getline(lines, line)) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    for (std::string w; words >> w;) {
      if (!keyword) {
        keyword = true;
        if (w.find("OFF") != std::string::npos) continue;
      }
      tokens.push_back(w);
    }
  }
  if (tokens.size() < 2) return 0; // Assimp says what is wrong
  const std::uint64_t vertices = count_of(file, tokens[0], "OFF vertex"), faces = count_of(file, tokens[1], "OFF face");
  // Each vertex takes at least 6 characters ("0 0 0\n"), each face 2 ("0\n").
  if (vertices > size / 6 || faces > size / 2 || vertices * 6 + faces * 2 > size)
    refuse(file, fmt::format("the OFF header declares {} vertices and {} faces, more than its {} bytes can hold "
                             "(truncated or corrupt?)",
                             limits::with_commas(vertices), limits::with_commas(faces), limits::with_commas(size)));
  return faces;
}

// OBJ: its face lines ("f ...", one triangle or more each), read a line at a time.
std::uint64_t obj_triangles(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::uint64_t faces = 0;
  for (std::string line; std::getline(in, line);) {
    const std::size_t start = line.find_first_not_of(" \t");
    if (start != std::string::npos && line.compare(start, 2, "f ") == 0) ++faces;
  }
  return faces;
}

// glTF 2.0 (.gltf, or the JSON chunk of a .glb): each node's mesh, counted once per node (Assimp's
// PreTransformVertices copies a mesh for every node that shows it), by its primitives' index or
// POSITION accessor counts (triangles, strips and fans). Anything unexpected: 0 (Assimp decides).
std::uint64_t gltf_triangles(const std::string& json_text) {
  const nlohmann::json j = nlohmann::json::parse(json_text, nullptr, false, true);
  if (!j.is_object()) return 0;
  auto array = [&](const nlohmann::json& o, const char* key) -> const nlohmann::json* {
    const auto it = o.find(key);
    return it != o.end() && it->is_array() ? &*it : nullptr;
  };
  auto index = [](const nlohmann::json& o, const char* key) -> std::int64_t {
    const auto it = o.find(key);
    return it != o.end() && it->is_number_unsigned()
               ? std::int64_t(std::min<std::uint64_t>(it->get<std::uint64_t>(), INT64_MAX))
               : -1;
  };
  const nlohmann::json *meshes = array(j, "meshes"), *accessors = array(j, "accessors"), *nodes = array(j, "nodes");
  if (!meshes || !accessors) return 0;
  auto accessor_count = [&](std::int64_t i) -> std::uint64_t {
    if (i < 0 || std::size_t(i) >= accessors->size() || !(*accessors)[std::size_t(i)].is_object()) return 0;
    return std::uint64_t(std::max<std::int64_t>(0, index((*accessors)[std::size_t(i)], "count")));
  };
  std::vector<std::uint64_t> mesh_triangles;
  for (const nlohmann::json& mesh : *meshes) {
    std::uint64_t triangles = 0;
    const nlohmann::json* primitives = mesh.is_object() ? array(mesh, "primitives") : nullptr;
    for (std::size_t p = 0; primitives && p < primitives->size(); ++p) {
      const nlohmann::json& primitive = (*primitives)[p];
      if (!primitive.is_object()) continue;
      const std::int64_t mode = primitive.contains("mode") ? index(primitive, "mode") : 4;
      std::uint64_t n = accessor_count(index(primitive, "indices"));
      if (!primitive.contains("indices") && primitive.contains("attributes") && primitive["attributes"].is_object())
        n = accessor_count(index(primitive["attributes"], "POSITION"));
      if (mode == 4) triangles += n / 3;
      if ((mode == 5 || mode == 6) && n >= 3) triangles += n - 2;
    }
    mesh_triangles.push_back(triangles);
  }
  std::uint64_t total = 0;
  for (std::size_t n = 0; nodes && n < nodes->size(); ++n) {
    if (!(*nodes)[n].is_object()) continue;
    const std::int64_t mesh = index((*nodes)[n], "mesh");
    if (mesh >= 0 && std::size_t(mesh) < mesh_triangles.size())
      total = std::min<std::uint64_t>(total + mesh_triangles[std::size_t(mesh)], UINT64_MAX / 2);
  }
  return total;
}

std::uint64_t glb_triangles(const fs::path& file, std::uint64_t size) {
  std::ifstream in(file, std::ios::binary);
  unsigned char head[20] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  if (!in) return 0;
  const std::uint32_t length = std::uint32_t(head[12]) | std::uint32_t(head[13]) << 8 | std::uint32_t(head[14]) << 16 |
                               std::uint32_t(head[15]) << 24;
  if (std::memcmp(head + 16, "JSON", 4) != 0) return 0;
  // Assimp allocates a chunk's claimed length before reading it (4 GB for a corrupt length field
  // in a file of a kilobyte, a fuzzer find, tests/fuzz/crashes/mesh_import): the JSON chunk and the
  // binary chunk after it must fit in the file.
  if (length > size - 20)
    refuse(file, fmt::format("truncated GLB: its JSON chunk claims {} bytes, the file has {} after the headers",
                             limits::with_commas(length), limits::with_commas(size - 20)));
  std::string json_text(length, '\0');
  in.read(json_text.data(), std::streamsize(length));
  if (!in) return 0;
  const std::uint64_t body = 20 + std::uint64_t(length) + (4 - length % 4) % 4; // chunks are 4-byte aligned
  unsigned char chunk[8] = {};
  in.seekg(std::streamoff(body));
  if (body + 8 <= size && in.read(reinterpret_cast<char*>(chunk), sizeof chunk)) {
    const std::uint32_t bin = std::uint32_t(chunk[0]) | std::uint32_t(chunk[1]) << 8 | std::uint32_t(chunk[2]) << 16 |
                              std::uint32_t(chunk[3]) << 24;
    if (bin > size - body - 8)
      refuse(file, fmt::format("truncated GLB: its binary chunk claims {} bytes, the file has {} after its header",
                               limits::with_commas(bin), limits::with_commas(size - body - 8)));
  }
  return gltf_triangles(json_text);
}

} // namespace

void check_mesh_header(const std::filesystem::path& file) {
  std::error_code ec;
  const std::uint64_t size = fs::file_size(file, ec);
  if (ec) refuse(file, "cannot read the mesh file's size");
  char magic[4] = {};
  std::ifstream(file, std::ios::binary).read(magic, sizeof magic);
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char ch) { return char(std::tolower(ch)); });
  std::uint64_t triangles = 0;
  const char* what = "faces";
  if (std::memcmp(magic, "ply", 3) == 0) {
    triangles = ply_triangles(file, size);
  } else if (std::memcmp(magic, "glTF", 4) == 0) {
    triangles = glb_triangles(file, size);
    what = "triangles";
  } else if (extension == ".off") {
    triangles = off_triangles(file, size);
  } else if (extension == ".obj") {
    triangles = obj_triangles(file);
  } else if (extension == ".gltf") {
    triangles = gltf_triangles(read_all(file, size));
    what = "triangles";
  }
  const std::uint64_t limit = limits::max_triangles();
  if (triangles > limit)
    refuse(file, fmt::format("the file declares {} {}, at least as many triangles; the limit is {} (MSM_MAX_TRIANGLES "
                             "raises it)",
                             limits::with_commas(triangles), what, limits::with_commas(limit)));
}

} // namespace msm::scene::detail
