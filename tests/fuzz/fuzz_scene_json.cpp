// Fuzz target: the scene JSON parser (load_scene_json), then what the renderer and the ray tracer
// do first with a scene: the camera and light matrices, the framing, the textures.
#include "fuzz_support.h"
#include "msm/scene/scene.h"

#include <cmath>
#include <string_view>

namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Files that scenes may name relative to their directory (the dictionary has their names).
void write_scene_files() {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
  msm::fuzz::write_bytes(msm::fuzz::scratch_dir() / "m.obj", obj.data(), obj.size());
  // A 1x1 RGBA PNG (one half-transparent grey texel).
  static const unsigned char png[] = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
      0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0x1f, 0x15, 0xc4, 0x89, 0x00, 0x00, 0x00,
      0x0d, 0x49, 0x44, 0x41, 0x54, 0x78, 0xda, 0x63, 0x68, 0x68, 0x68, 0x68, 0x00, 0x00, 0x04, 0x84, 0x02, 0x01,
      0x8c, 0xe3, 0x7d, 0x41, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  msm::fuzz::write_bytes(msm::fuzz::scratch_dir() / "t.png", png, sizeof png);
}

void check_scene(const msm::scene::Scene& s) {
  using namespace msm::scene;
  MSM_FUZZ_CHECK(!s.objects.empty());
  MSM_FUZZ_CHECK(!s.lights.empty() && s.lights.size() <= std::size_t(kMaxLights));
  MSM_FUZZ_CHECK(std::isfinite(s.camera.near) && std::isfinite(s.camera.far) && s.camera.near < s.camera.far);
  for (const Object& o : s.objects) {
    const Mesh& m = o.mesh;
    MSM_FUZZ_CHECK(o.material < s.materials.size());
    MSM_FUZZ_CHECK(m.normals.size() == m.positions.size() && m.uvs.size() == m.positions.size());
    MSM_FUZZ_CHECK(!m.indices.empty() && m.indices.size() % 3 == 0);
    for (std::uint32_t i : m.indices) MSM_FUZZ_CHECK(i < m.positions.size());
    for (const glm::vec3& p : m.positions) MSM_FUZZ_CHECK(finite(p));
  }
  for (std::size_t i = 0; i < s.lights.size(); ++i) {
    MSM_FUZZ_CHECK(finite(s.lights[i].towards_light));
    (void)s.light_frame(i);
  }
  (void)s.camera_view_projection(16.0f / 9.0f);
  for (const Material& m : s.materials) {
    (void)albedo_image(m);
    (void)opacity_image(m);
  }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  msm::fuzz::lower_limits();
  write_scene_files();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    check_scene(msm::scene::load_scene_json(text, msm::fuzz::scratch_dir(), "fuzz.json"));
  } catch (const msm::scene::SceneError& e) { msm::fuzz::rejected(e); }
  return 0;
}
