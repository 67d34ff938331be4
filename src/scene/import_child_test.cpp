// import_model runs Assimp in a child process (import_child.cpp): a crash, an abort, a sanitizer's
// exit, an endless loop or a runaway allocation in the child is a SceneError naming the file, and
// this process goes on (the next import works); the parts come back exactly as the in-process
// import makes them; the child's bytes are checked (every truncation and corruption is refused or
// gives consistent parts).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "internal.h"
#include "msm/scene/scene.h"
#include "msm/test/gltf_writer.h"
#include "msm/test/temp_dir.h"

#if defined(__SANITIZE_ADDRESS__)
#define MSM_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MSM_TEST_SANITIZED 1
#endif
#endif

using namespace msm::scene;
namespace fs = std::filesystem;
using msm::test::TempDir;

namespace {

const char* const kCube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                          "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";

// Sets the child's hook for one test, and an environment variable, both undone at the end.
struct Hook {
  Hook(void (*hook)(), const char* variable = nullptr, const char* value = nullptr) : variable(variable) {
    detail::import_child_hook = hook;
    if (variable) ::setenv(variable, value, 1);
  }
  ~Hook() {
    detail::import_child_hook = nullptr;
    if (variable) ::unsetenv(variable);
  }
  const char* variable;
};

// The message of the SceneError import_model throws, or a failure.
std::string import_error(const fs::path& file) {
  try {
    (void)import_model(file);
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), file.string());
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a SceneError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no SceneError";
  return "";
}

// import_model(file) fails with a SceneError whose message contains `expected`.
void expect_import_error(const fs::path& file, const std::string& expected) {
  const std::string what = import_error(file);
  EXPECT_NE(what.find(expected), std::string::npos) << what;
}

void say(const char* text) { (void)!::write(2, text, std::strlen(text)); }

// The importer still works (this process survived the child).
void expect_cube(const fs::path& file) {
  const std::vector<ModelPart> parts = import_model(file);
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_EQ(parts[0].mesh.triangle_count(), 12u);
}

void expect_same(const std::vector<ModelPart>& a, const std::vector<ModelPart>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].name, b[i].name);
    EXPECT_EQ(a[i].mesh.positions, b[i].mesh.positions);
    EXPECT_EQ(a[i].mesh.normals, b[i].mesh.normals);
    EXPECT_EQ(a[i].mesh.uvs, b[i].mesh.uvs);
    EXPECT_EQ(a[i].mesh.indices, b[i].mesh.indices);
    ASSERT_EQ(a[i].material.has_value(), b[i].material.has_value());
    if (!a[i].material) continue;
    const Material &x = *a[i].material, &y = *b[i].material;
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.albedo, y.albedo);
    EXPECT_EQ(x.albedo_texture, y.albedo_texture);
    EXPECT_EQ(x.opacity, y.opacity);
    EXPECT_EQ(x.opacity_texture, y.opacity_texture);
    EXPECT_EQ(x.opacity_from_alpha, y.opacity_from_alpha);
    EXPECT_EQ(x.alpha_cutoff, y.alpha_cutoff);
    EXPECT_EQ(x.double_sided, y.double_sided);
    EXPECT_EQ(x.transmission_color, y.transmission_color);
    for (const auto& [p, q] :
         {std::pair(x.albedo_pixels, y.albedo_pixels), std::pair(x.opacity_pixels, y.opacity_pixels)}) {
      ASSERT_EQ(p != nullptr, q != nullptr);
      if (!p) continue;
      EXPECT_EQ(p->width, q->width);
      EXPECT_EQ(p->height, q->height);
      EXPECT_EQ(p->rgba, q->rgba);
    }
  }
}

// A .glb of the four alpha-mode materials (alpha_modes_model): MASK (albedo and opacity) and
// OPAQUE share one embedded texture.
fs::path write_textured(const TempDir& dir) {
  using namespace msm::scene::testing;
  GltfModel model = alpha_modes_model(
      {.width = 2, .height = 2, .rgba = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0, 9, 9, 9, 255}});
  const fs::path file = dir.path() / "textured.glb";
  write_gltf(file, model);
  return file;
}

} // namespace

// Each test's folder, with a cube to import in it.
class ImportChild : public ::testing::Test {
 protected:
  TempDir dir{"msm_import_child_test"};
  const fs::path cube = dir.write("cube.obj", kCube);
};

// A segmentation fault inside the child: the message names the file and the signal, what the
// child printed is quoted (its stdout and stderr go to the parent, not to the terminal), and the
// next import works.
TEST_F(ImportChild, CrashIsASceneError) {
  {
    Hook hook([] {
      (void)!::write(1, "the child says this\n", 20);
      std::raise(SIGSEGV);
    });
    expect_import_error(cube, "cube.obj: Assimp crashed while reading the mesh (signal 11, Segmentation fault: "
                              "the child says this)");
  }
  expect_cube(cube);
}

// An abort (a heap check of the C library), and an exit with a sanitizer's status after its report.
TEST_F(ImportChild, AbortAndSanitizerExit) {
  {
    Hook hook([] {
      say("malloc(): corrupted top size\n");
      std::abort();
    });
    expect_import_error(cube,
                        "Assimp crashed while reading the mesh (signal 6, Aborted: malloc(): corrupted top size)");
  }
  {
    Hook hook([] {
      say("\n==4242==ERROR: AddressSanitizer: heap-use-after-free on address 0x6020\nmore lines\n");
      ::_exit(1);
    });
    expect_import_error(cube,
                        "(exit status 1: ==4242==ERROR: AddressSanitizer: heap-use-after-free on address 0x6020)");
  }
  expect_cube(cube);
}

// An endless loop: killed after MSM_IMPORT_TIMEOUT_S (1 s here; the default is 600 s).
TEST_F(ImportChild, EndlessLoopEndsAtTheTimeout) {
  EXPECT_EQ(detail::import_timeout_seconds(), 600.0);
  {
    Hook hook(
        [] {
          for (;;) ::pause();
        },
        "MSM_IMPORT_TIMEOUT_S", "1");
    EXPECT_EQ(detail::import_timeout_seconds(), 1.0);
    const auto start = std::chrono::steady_clock::now();
    const std::string what = import_error(cube);
    EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::seconds(1)); // it waited, then gave up
    EXPECT_NE(what.find("cube.obj: Assimp did not finish reading the mesh within 1 s (MSM_IMPORT_TIMEOUT_S raises it)"),
              std::string::npos)
        << what;
  }
  expect_cube(cube);
}

// A runaway allocation ends at the child's address-space limit (this process's own plus
// MSM_MAX_MEMORY_MB): std::bad_alloc in the child, a SceneError here. The hook stops at 64 GiB of
// untouched blocks, so that a missing limit fails the test instead of exhausting the machine.
TEST_F(ImportChild, RunawayAllocationEndsAtTheMemoryLimit) {
#ifdef MSM_TEST_SANITIZED
  GTEST_SKIP() << "no address-space limit under sanitizers (their shadow memory reserves terabytes)";
#else
  {
    Hook hook(
        [] {
          static std::vector<std::unique_ptr<char[]>> blocks;
          for (int i = 0; i < 64 * 1024; ++i) blocks.emplace_back(new char[1 << 20]);
        },
        "MSM_MAX_MEMORY_MB", "64");
    expect_import_error(cube,
                        "cube.obj: Assimp ran out of memory reading the mesh (the limit is 64 MiB: MSM_MAX_MEMORY_MB "
                        "raises it)");
  }
  expect_cube(cube);
#endif
}

// The child's SceneError comes back with its three parts.
TEST_F(ImportChild, SceneErrorTravelsBack) {
  Hook hook([] { throw SceneError("some.obj", "/objects/1", "a problem found in the child"); });
  try {
    (void)import_model(cube);
    ADD_FAILURE() << "no SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "some.obj");
    EXPECT_EQ(e.where(), "/objects/1");
    EXPECT_EQ(e.problem(), "a problem found in the child");
  }
}

// The result larger than MSM_MAX_MEMORY_MB: refused (by the parent's read cap, or by the child's
// address-space limit before it), never read without end.
TEST_F(ImportChild, ResultOverTheMemoryLimitIsRefused) {
  std::string text;
  const int n =
      60000; // a fan of triangles (0 0 0), (i 1 0), (i+1 1 0): 60,002 vertices of 32 B and 60,000 triangles of 12 B: 2.6 MB
  text += "v 0 0 0\n";
  for (int i = 0; i <= n; ++i) text += "v " + std::to_string(i) + " 1 0\n";
  for (int i = 1; i <= n; ++i) text += "f 1 " + std::to_string(i + 1) + " " + std::to_string(i + 2) + "\n";
  const fs::path fan = dir.write("fan.obj", text);
  {
    Hook hook(nullptr, "MSM_MAX_MEMORY_MB", "1");
    expect_import_error(fan, "MSM_MAX_MEMORY_MB");
  }
  EXPECT_EQ(import_mesh(fan).triangle_count(), std::size_t(n));
}

// The parts through the child equal those of the in-process import: materials, the embedded
// texture's texels, one Image shared by the material's albedo and opacity as before.
TEST_F(ImportChild, PartsComeBackExactly) {
  const fs::path file = write_textured(dir);
  const std::vector<ModelPart> here = detail::import_model_in_process(file);
  const std::vector<ModelPart> there = import_model(file);
  ASSERT_EQ(there.size(), 4u);
  expect_same(here, there);
  const Material& mask = *there[0].material;
  ASSERT_TRUE(mask.albedo_pixels);
  EXPECT_EQ(mask.albedo_pixels, mask.opacity_pixels);
  EXPECT_EQ(there[2].material->albedo_pixels, mask.albedo_pixels); // "opaque", the same texture
  EXPECT_EQ(mask.albedo_pixels->rgba.size(), 16u);
  const std::vector<ModelPart> cube = import_model(dir.write("cube.obj", kCube));
  expect_same(detail::import_model_in_process(dir.path() / "cube.obj"), cube);
}

// The child's bytes are not trusted: every truncation is refused; counts and indices set to any
// value and random byte changes (fixed seed) are refused, or give parts that keep the invariants
// (indices within the vertices, normals and uvs one per position, finite positions).
TEST_F(ImportChild, CorruptResultIsRefused) {
  const fs::path file = write_textured(dir);
  const std::string bytes = detail::serialize_model(detail::import_model_in_process(file));
  expect_same(detail::deserialize_model(bytes, file), detail::import_model_in_process(file));
  for (std::size_t size = 0; size < bytes.size(); ++size) {
    try {
      (void)detail::deserialize_model(std::string_view(bytes).substr(0, size), file);
      ADD_FAILURE() << "a truncation to " << size << " of " << bytes.size() << " bytes was accepted";
    } catch (const SceneError& e) {
      ASSERT_NE(std::string(e.what()).find("the import process sent an inconsistent result"), std::string::npos)
          << e.what();
    }
  }
  auto check = [&](const std::string& changed) {
    try {
      for (const ModelPart& part : detail::deserialize_model(changed, file)) {
        const Mesh& m = part.mesh;
        ASSERT_EQ(m.normals.size(), m.positions.size());
        ASSERT_EQ(m.uvs.size(), m.positions.size());
        ASSERT_EQ(m.indices.size() % 3, 0u);
        for (std::uint32_t i : m.indices) ASSERT_LT(i, m.positions.size());
        for (const glm::vec3& p : m.positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
        if (part.material && part.material->albedo_pixels) {
          const Image& image = *part.material->albedo_pixels;
          ASSERT_EQ(image.rgba.size(), 4u * std::size_t(image.width) * std::size_t(image.height));
        }
      }
    } catch (const SceneError&) {}
  };
  int accepted = 0;
  for (std::size_t at = 0; at + 8 <= bytes.size(); ++at)
    for (const std::uint64_t value : {std::uint64_t(0), std::uint64_t(1) << 32, ~std::uint64_t(0), std::uint64_t(3)}) {
      std::string changed = bytes;
      std::memcpy(changed.data() + at, &value, 8);
      check(changed);
      try {
        (void)detail::deserialize_model(changed, file);
        ++accepted;
      } catch (const SceneError&) {}
    }
  EXPECT_GT(accepted, 0); // some overwrite only floats or texels: still a valid result
  std::mt19937 random(1);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string changed = bytes;
    for (int k = 0; k < 4; ++k) changed[random() % changed.size()] = char(random());
    check(changed);
  }
}
