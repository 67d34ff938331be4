// JSON scene loading, built-in scenes and the camera/light matrices.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "internal.h"
#include "msm/local_light.h"
#include "msm/probe/probe.h"
#include "msm/util/limits.h"

namespace msm::scene {
namespace {

// The largest irradiance of a light (each RGB component): the shading sums the irradiance of every
// light of a frame and as many luminance weights in single precision (shading.glsl), which stay
// finite for kMaxLights lights of at most FLT_MAX / kMaxLights ≈ 1.3e36 each (above, the weights'
// sum overflowed to inf and the shadow buffer's visibility became inf / inf = NaN).
constexpr float kMaxIrradiance = 1e36f;
// The largest radiant intensity of a spot or point light: at the shortest distance the shading
// takes (MSM_LOCAL_LIGHT_MIN_DISTANCE2) its irradiance stays below kMaxIrradiance.
constexpr float kMaxIntensity = 1e27f;

constexpr std::string_view kDirectionalKeys[] = {"towards_light", "irradiance", "angular_extent_deg",
                                                 "angular_height_deg", "x_axis"};
constexpr std::string_view kSpotKeys[] = {"position", "direction", "inner_cone_deg", "outer_cone_deg",
                                          "range",    "intensity", "radius"};
constexpr std::string_view kPointKeys[] = {"position", "range", "intensity", "radius"};

constexpr LightKindInfo kLightKinds[] = {
    {LightKind::directional, "directional", kDirectionalKeys,
     "orthographic, fitted to what the camera sees (ShadowFraming)", 1,
     "distance along the light's travel, affine: 0 at the box's near side, 1 at its far side",
     "parallel rays towards towards_light, unbounded; a disc or rectangle of directions when soft", true},
    {LightKind::spot, "spot", kSpotKeys, "perspective, the outer cone's field of view", 1, "radial distance / range",
     "a shadow ray to the light's position (bounded by the distance)", true},
    {LightKind::point, "point", kPointKeys,
     "six perspective faces of a cube, 90 degrees each and a guard band of the filter's or soft kernel's reach", 6,
     "radial distance / range", "a shadow ray to the light's position (bounded by the distance)", true},
};

// What is wrong with a spot or point light (the key and the problem), or nothing: the one set of
// rules for the scene's "lights" and the lights imported from glTF files.
struct LightProblem {
  std::string key, problem;
};
std::string range_text(float lo, float hi, bool open_lo, bool open_hi, float x) {
  return fmt::format("must be in {}{:g}, {:g}{} (got {:g})", open_lo ? '(' : '[', lo, hi, open_hi ? ')' : ']', x);
}
std::optional<LightProblem> local_light_problem(const LocalLight& l) {
  if (glm::any(glm::greaterThan(glm::abs(l.position), glm::vec3(kMaxSize))))
    return LightProblem{"position", fmt::format("|component| must be at most {:g}", kMaxSize)};
  if (l.spot()) {
    if (!(l.outer_cone_deg > 0.0f && l.outer_cone_deg < 90.0f))
      return LightProblem{"outer_cone_deg", range_text(0.0f, 90.0f, true, true, l.outer_cone_deg)};
    if (!(l.inner_cone_deg >= 0.0f && l.inner_cone_deg < 90.0f))
      return LightProblem{"inner_cone_deg", range_text(0.0f, 90.0f, false, true, l.inner_cone_deg)};
    if (l.inner_cone_deg > l.outer_cone_deg)
      return LightProblem{"inner_cone_deg",
                          fmt::format("{:g} degrees is wider than outer_cone_deg {:g}: the inner cone "
                                      "(full intensity) lies within the outer one",
                                      l.inner_cone_deg, l.outer_cone_deg)};
  }
  if (l.range != LocalLight::kInfiniteRange && !(l.range > 0.0f && l.range <= kMaxCameraFar))
    return LightProblem{"range", range_text(0.0f, kMaxCameraFar, true, false, l.range)};
  if (glm::any(glm::lessThan(l.intensity, glm::vec3(0.0f)))) return LightProblem{"intensity", "must be >= 0"};
  if (glm::any(glm::greaterThan(l.intensity, glm::vec3(kMaxIntensity))))
    return LightProblem{"intensity", fmt::format("must be at most {:g} W/sr", kMaxIntensity)};
  if (!(l.radius >= 0.0f && l.radius <= kMaxSize))
    return LightProblem{"radius", range_text(0.0f, kMaxSize, false, false, l.radius)};
  return std::nullopt;
}

using nlohmann::json;
namespace fs = std::filesystem;

// Generated from scenes/*.json at configure time: {name, text} pairs.
struct BuiltinScene {
  std::string_view name, json;
};
constexpr BuiltinScene kBuiltinScenes[] = {
#include "builtin_scenes.inc"
};

// Scene, object and material names: labels in messages, outputs and the viewer, refused beyond this.
constexpr std::size_t kMaxNameBytes = 256;

std::string compose(const std::string& file, const std::string& where, const std::string& problem) {
  std::string s;
  if (!file.empty()) s += file + ": ";
  if (!where.empty()) s += where + ": ";
  return s + problem;
}

// The probe's area lights (msm::probe: cube map, median cut, Kneiphof §4.1) as discs of the light's
// cone with the irradiance a facing surface receives (Eq. 18), with their sub-lights where the probe
// asks for them (ProbeLighting::sub_lights). Throws msm::probe::ProbeError.
std::vector<DirectionalLight> probe_directional_lights(const ProbeLighting& p) {
  std::vector<DirectionalLight> out;
  for (const msm::probe::ProbeLight& pl :
       msm::probe::probe_lights_with_sub_lights(p.file == "sky" ? "sky" : p.file.string(), p.size, p.lights,
                                                p.sub_lights, p.rotation_deg, p.intensity, p.horizon_split))
    out.push_back(light_of_probe_light(pl));
  return out;
}

// What is wrong with a probe's "sub_lights" (empty: nothing): 0..256, and the horizon split's cut
// makes at least ten regions.
std::string sub_lights_problem(const ProbeLighting& p) {
  if (p.sub_lights < 0 || p.sub_lights > 256)
    return fmt::format("{} sub-lights: must be in [0, 256] (0: none)", p.sub_lights);
  if (p.horizon_split && p.sub_lights > 0 && p.sub_lights < msm::probe::kHorizonSplitMinLights)
    return fmt::format("{} sub-lights: the horizon split makes {} to 256 regions", p.sub_lights,
                       msm::probe::kHorizonSplitMinLights);
  return {};
}

// Vulkan clip space: y down in NDC.
glm::mat4 flip_y(const glm::mat4& p) {
  glm::mat4 f(1.0f);
  f[1][1] = -1.0f;
  return f * p;
}

class Parser {
 public:
  Parser(std::string file, fs::path base) : file_(file.empty() ? "<json>" : std::move(file)), base_(std::move(base)) {}

  // One "lights" entry (parse_light).
  DeclaredLight parse_light(std::string_view text, const std::string& ptr) const {
    json j;
    try {
      j = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const json::exception& e) { fail(ptr, fmt::format("malformed JSON: {}", e.what())); }
    DeclaredLight d;
    d.kind = light_type(j, ptr);
    if (d.kind == LightKind::directional)
      d.directional = light(j, ptr);
    else
      d.local = local_light(j, ptr, d.kind);
    return d;
  }

  Scene parse(std::string_view text) {
    if (const std::string encoding = wide_encoding(text); !encoding.empty())
      fail("", fmt::format("the scene is {}, not UTF-8: save it as UTF-8", encoding));
    json root;
    try {
      root = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const json::exception& e) { // parse_error, out_of_range (number overflow), ...
      fail("", fmt::format("malformed JSON: {}", e.what()));
    }
    keys(root, "",
         {"msm_scene", "name", "camera", "light", "lights", "shadow_map", "medium", "probe", "materials", "objects"});
    const json* version = find(root, "msm_scene");
    if (!version) fail("/msm_scene", "required key missing (the format version, 1)");
    if (!version->is_number_integer() || version->get<long long>() != 1)
      fail("/msm_scene", "unsupported format version (only 1 exists)");
    Scene s;
    s.source = file_;
    if (const json* v = find(root, "name")) s.name = name(*v, "/name");
    if (const json* v = find(root, "camera")) s.camera = camera(*v, "/camera");
    const json* light_json = find(root, "light");
    const json* lights_json = find(root, "lights");
    const json* probe_json = find(root, "probe");
    const json* objects_json = find(root, "objects");
    const bool imports_lights = objects_json && objects_json->is_array() &&
                                std::any_of(objects_json->begin(), objects_json->end(),
                                            [](const json& o) { return o.is_object() && o.contains("import_lights"); });
    if (!light_json && !lights_json && !probe_json && !imports_lights)
      fail("/light", "required key missing (or \"lights\": a list of them, a \"probe\", or an object's "
                     "\"import_lights\")");
    if (light_json && lights_json) fail("/lights", "give either \"light\" or \"lights\", not both");
    if (!light_json && !lights_json) {
      s.lights.clear();
    } else if (light_json) {
      if (light_type(*light_json, "/light") != LightKind::directional)
        fail("/light/type", "\"light\" is one directional light: give spot and point lights in \"lights\"");
      s.lights = {light(*light_json, "/light")};
    } else {
      if (!lights_json->is_array() || lights_json->empty() || lights_json->size() > size_t(kMaxLights))
        fail("/lights", fmt::format("must be a list of 1 to {} lights", kMaxLights));
      s.lights.clear();
      for (size_t i = 0; i < lights_json->size(); ++i) {
        const json& entry = (*lights_json)[i];
        const std::string ptr = fmt::format("/lights/{}", i);
        const LightKind kind = light_type(entry, ptr);
        if (kind == LightKind::directional)
          s.lights.push_back(light(entry, ptr));
        else
          s.local_lights.push_back(local_light(entry, ptr, kind));
      }
    }
    if (const json* v = find(root, "shadow_map")) s.shadow = framing(*v, "/shadow_map");
    if (const json* v = find(root, "medium")) s.medium = medium(*v, "/medium");
    if (probe_json) probe_lighting(*probe_json, "/probe", s);

    Material default_material;
    default_material.name = "default";
    s.materials.push_back(default_material);
    if (const json* mats = find(root, "materials")) {
      if (!mats->is_object()) fail("/materials", "must be an object mapping names to materials");
      for (const auto& [name, m] : mats->items()) {
        const std::string ptr = "/materials/" + escape(name);
        check_name_length(name, ptr);
        named_[name] = static_cast<std::uint32_t>(s.materials.size());
        s.materials.push_back(material(m, ptr));
        s.materials.back().name = name;
      }
    }
    const json* objs = find(root, "objects");
    if (!objs) fail("/objects", "required key missing");
    if (!objs->is_array() || objs->empty()) fail("/objects", "must be a non-empty array");
    for (std::size_t i = 0; i < objs->size(); ++i) object((*objs)[i], fmt::format("/objects/{}", i), i, s);
    if (s.lights.empty() && s.local_lights.empty())
      fail("/objects", "no light: the objects' \"import_lights\" files hold none, and the scene declares none");
    return s;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw SceneError(file_, where, problem);
  }

  // JSON pointer escaping, of a key shortened for messages.
  static std::string escape(const std::string& key) {
    std::string r;
    for (char c : shortened(key)) r += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
    return r;
  }

  // A name as messages show it: at most 48 bytes of it (whole UTF-8 characters) and its length.
  static std::string shortened(const std::string& text) {
    if (text.size() <= 64) return text;
    std::size_t end = 48;
    while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end; // not mid-character
    return fmt::format("{}... ({} bytes)", text.substr(0, end), text.size());
  }

  // Scene, object and material names are labels (messages, JSON outputs, the viewer's panel): a
  // name longer than kMaxNameBytes is refused, not echoed whole into every message and output.
  void check_name_length(const std::string& text, const std::string& ptr) const {
    if (text.size() > kMaxNameBytes)
      fail(ptr, fmt::format("a name of {} bytes ('{}'): names are at most {} bytes", text.size(), shortened(text),
                            kMaxNameBytes));
  }

  std::string name(const json& v, const std::string& ptr) const {
    std::string text = string(v, ptr);
    check_name_length(text, ptr);
    return text;
  }

  // A scene saved as UTF-16 or UTF-32 (with or without a byte-order mark): nlohmann::json reads
  // UTF-8 only, and would report "invalid literal" at the first byte. Empty: not one of those.
  static std::string wide_encoding(std::string_view text) {
    const auto byte = [&](std::size_t i) { return i < text.size() ? static_cast<unsigned char>(text[i]) : 0x100u; };
    if (byte(0) == 0x00 && byte(1) == 0x00 && byte(2) == 0xFE && byte(3) == 0xFF) return "UTF-32 (big-endian)";
    if (byte(0) == 0xFF && byte(1) == 0xFE && byte(2) == 0x00 && byte(3) == 0x00) return "UTF-32 (little-endian)";
    if (byte(0) == 0xFE && byte(1) == 0xFF) return "UTF-16 (big-endian, byte-order mark FE FF)";
    if (byte(0) == 0xFF && byte(1) == 0xFE) return "UTF-16 (little-endian, byte-order mark FF FE)";
    // Without a mark: JSON starts with ASCII, so a NUL beside the first character gives it away.
    if (byte(0) == 0x00 && byte(1) != 0x00 && byte(1) < 0x80) return "UTF-16 (big-endian, no byte-order mark)";
    if (byte(0) != 0x00 && byte(0) < 0x80 && byte(1) == 0x00) return "UTF-16 (little-endian, no byte-order mark)";
    return {};
  }

  static const json* find(const json& obj, const char* key) {
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  void keys(const json& obj, const std::string& ptr, std::initializer_list<std::string_view> allowed) const {
    if (!obj.is_object()) fail(ptr.empty() ? "/" : ptr, fmt::format("must be a JSON object (got {})", obj.type_name()));
    for (const auto& [key, value] : obj.items())
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        fail(ptr + "/" + escape(key), fmt::format("unknown key (allowed: {})", fmt::join(allowed, ", ")));
  }

  std::string string(const json& v, const std::string& ptr) const {
    if (!v.is_string()) fail(ptr, fmt::format("must be a string (got {})", v.type_name()));
    return v.get<std::string>();
  }

  bool boolean(const json& v, const std::string& ptr) const {
    if (!v.is_boolean()) fail(ptr, fmt::format("must be true or false (got {})", v.type_name()));
    return v.get<bool>();
  }

  float number(const json& v, const std::string& ptr) const {
    if (!v.is_number()) fail(ptr, fmt::format("must be a number (got {})", v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d) || std::abs(d) > 3e38) fail(ptr, "must be a finite number");
    return static_cast<float>(d);
  }

  float number_in(const json& v, const std::string& ptr, float lo, float hi, bool open_lo, bool open_hi) const {
    const float x = number(v, ptr);
    if ((open_lo ? x <= lo : x < lo) || (open_hi ? x >= hi : x > hi))
      fail(ptr,
           fmt::format("must be in {}{:g}, {:g}{} (got {:g})", open_lo ? '(' : '[', lo, hi, open_hi ? ')' : ']', x));
    return x;
  }

  int integer(const json& v, const std::string& ptr) const {
    if (!v.is_number()) fail(ptr, fmt::format("must be an integer (got {})", v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d) || d != std::floor(d)) fail(ptr, "must be an integer");
    if (d < -1e9 || d > 1e9) fail(ptr, fmt::format("absurd value {:g}", d));
    return static_cast<int>(d);
  }

  template <int N>
  glm::vec<N, float> vec(const json& v, const std::string& ptr) const {
    if (!v.is_array() || v.size() != N) fail(ptr, fmt::format("must be an array of {} numbers", N));
    glm::vec<N, float> r;
    for (int i = 0; i < N; ++i) r[i] = number(v[i], fmt::format("{}/{}", ptr, i));
    return r;
  }

  glm::vec3 direction(const json& v, const std::string& ptr) const {
    const glm::vec3 d = vec<3>(v, ptr);
    const float len = glm::length(d);
    if (!(len > 1e-20f) || !std::isfinite(len)) fail(ptr, "must be a non-zero direction");
    return d / len;
  }

  Camera camera(const json& j, const std::string& ptr) const {
    keys(j, ptr, {"position", "target", "up", "fov_y_deg", "near", "far"});
    Camera c;
    if (const json* v = find(j, "position")) c.position = vec<3>(*v, ptr + "/position");
    if (const json* v = find(j, "target")) c.target = vec<3>(*v, ptr + "/target");
    if (const json* v = find(j, "up")) c.up = direction(*v, ptr + "/up");
    if (const json* v = find(j, "fov_y_deg")) c.fov_y_deg = number_in(*v, ptr + "/fov_y_deg", 0.0f, 180.0f, true, true);
    if (const json* v = find(j, "near")) c.near = number_in(*v, ptr + "/near", kMinCameraNear, kMaxSize, false, false);
    if (const json* v = find(j, "far"))
      c.far = number_in(*v, ptr + "/far", kMinCameraNear, kMaxCameraFar, false, false);
    if (!(c.far > c.near)) fail(ptr + "/far", "must be greater than near");
    if (double(c.far) / double(c.near) > kMaxCameraDepthRatio)
      fail(ptr + "/far", fmt::format("far / near = {:g} is more than {:g}: the camera's depth buffer would not "
                                     "separate surfaces (raise near or lower far)",
                                     double(c.far) / double(c.near), kMaxCameraDepthRatio));
    const glm::vec3 view = c.target - c.position;
    if (!(glm::length(view) > 0.0f)) fail(ptr + "/target", "must differ from position");
    if (!(glm::length(glm::cross(glm::normalize(view), c.up)) > 1e-4f))
      fail(ptr + "/up", "must not be parallel to the view direction");
    return c;
  }

  // A "lights" entry's "type" (default: directional); then only that kind's keys are allowed.
  LightKind light_type(const json& j, const std::string& ptr) const {
    if (!j.is_object()) fail(ptr, fmt::format("must be a JSON object (got {})", j.type_name()));
    const json* t = find(j, "type");
    if (!t) return LightKind::directional;
    const std::string name = string(*t, ptr + "/type");
    if (const std::optional<LightKind> kind = parse_light_kind(name)) return *kind;
    std::vector<std::string_view> names;
    for (const LightKindInfo& k : light_kinds()) names.push_back(k.name);
    fail(ptr + "/type", fmt::format("unknown light type '{}' (allowed: {})", shortened(name), fmt::join(names, ", ")));
  }

  // The keys of a light of `kind` (its declaration's) and "type".
  void light_keys(const json& j, const std::string& ptr, LightKind kind) const {
    std::vector<std::string_view> allowed(light_kind(kind).keys.begin(), light_kind(kind).keys.end());
    allowed.push_back("type");
    for (const auto& [key, value] : j.items())
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        fail(ptr + "/" + escape(key),
             fmt::format("unknown key of a {} light (allowed: {})", light_kind(kind).name, fmt::join(allowed, ", ")));
  }

  LocalLight local_light(const json& j, const std::string& ptr, LightKind kind) const {
    light_keys(j, ptr, kind);
    LocalLight l;
    l.kind = kind;
    const json* position = find(j, "position");
    if (!position) fail(ptr + "/position", "required key missing (where the light is)");
    l.position = vec<3>(*position, ptr + "/position");
    if (l.spot()) {
      const json* d = find(j, "direction");
      if (!d) fail(ptr + "/direction", "required key missing (the direction the spot light shines in)");
      l.direction = direction(*d, ptr + "/direction");
      if (const json* v = find(j, "outer_cone_deg")) l.outer_cone_deg = number(*v, ptr + "/outer_cone_deg");
      if (const json* v = find(j, "inner_cone_deg")) l.inner_cone_deg = number(*v, ptr + "/inner_cone_deg");
    }
    if (const json* v = find(j, "range")) l.range = number(*v, ptr + "/range");
    if (const json* v = find(j, "intensity")) l.intensity = vec<3>(*v, ptr + "/intensity");
    if (const json* v = find(j, "radius")) l.radius = number(*v, ptr + "/radius");
    if (const auto problem = local_light_problem(l)) fail(ptr + "/" + problem->key, problem->problem);
    return l;
  }

  // A glTF file's KHR_lights_punctual lights (detail::gltf_lights), moved by the object's transform,
  // appended to the scene's lights; checked as the scene's own ("import_lights").
  void import_lights(const fs::path& file, const Transform& transform, const std::string& ptr, Scene& s) const {
    std::vector<detail::FileLight> lights;
    try {
      lights = detail::gltf_lights(file);
    } catch (const SceneError& e) { fail(ptr, fmt::format("{} ({})", e.problem(), file.string())); }
    const glm::mat4 m = transform.matrix();
    for (const detail::FileLight& f : lights) {
      const std::string what =
          fmt::format("{}'s KHR_lights_punctual light {} ('{}')", file.filename().string(), f.index, shortened(f.name));
      const glm::vec3 direction = transform.rotate * (f.direction / transform.scale);
      if (!(glm::length(direction) > 0.0f)) fail(ptr, what + ": its node's transform has no direction left");
      if (f.kind == LightKind::directional) {
        DirectionalLight l;
        l.towards_light = -glm::normalize(direction);
        l.irradiance = f.intensity;
        if (glm::any(glm::lessThan(l.irradiance, glm::vec3(0.0f))) ||
            glm::any(glm::greaterThan(l.irradiance, glm::vec3(kMaxIrradiance))))
          fail(ptr, fmt::format("{}: irradiance must be in [0, {:g}]", what, kMaxIrradiance));
        s.lights.push_back(l);
        continue;
      }
      LocalLight l;
      l.kind = f.kind;
      l.position = glm::vec3(m * glm::vec4(f.position, 1.0f));
      l.direction = glm::normalize(direction);
      l.inner_cone_deg = f.inner_cone_deg;
      l.outer_cone_deg = f.outer_cone_deg;
      // A range scales with the object (the largest of its scales: the light reaches at least as far).
      if (f.range) l.range = *f.range * std::max({transform.scale.x, transform.scale.y, transform.scale.z});
      l.intensity = f.intensity;
      if (const auto problem = local_light_problem(l))
        fail(ptr, fmt::format("{}: {}: {}", what, problem->key, problem->problem));
      s.local_lights.push_back(l);
    }
    if (s.lights.size() + s.local_lights.size() > std::size_t(kMaxLights))
      fail(ptr,
           fmt::format("{} lights with the file's: at most {}", s.lights.size() + s.local_lights.size(), kMaxLights));
  }

  DirectionalLight light(const json& j, const std::string& ptr) const {
    light_keys(j, ptr, LightKind::directional);
    DirectionalLight l;
    const json* d = find(j, "towards_light");
    if (!d) fail(ptr + "/towards_light", "required key missing (direction from the scene towards the light)");
    l.towards_light = direction(*d, ptr + "/towards_light");
    if (const json* v = find(j, "irradiance")) {
      l.irradiance = vec<3>(*v, ptr + "/irradiance");
      if (glm::any(glm::lessThan(l.irradiance, glm::vec3(0.0f)))) fail(ptr + "/irradiance", "must be >= 0");
      if (glm::any(glm::greaterThan(l.irradiance, glm::vec3(kMaxIrradiance))))
        fail(ptr + "/irradiance",
             fmt::format("must be at most {:g} (the shading sums up to {} lights in single precision)", kMaxIrradiance,
                         kMaxLights));
    }
    if (const json* v = find(j, "angular_extent_deg"))
      l.angular_extent_deg = number_in(*v, ptr + "/angular_extent_deg", 0.0f, 90.0f, false, true);
    if (const json* v = find(j, "angular_height_deg"))
      l.angular_height_deg = number_in(*v, ptr + "/angular_height_deg", 0.0f, 90.0f, false, true);
    if (const json* v = find(j, "x_axis")) {
      const glm::vec3 x = direction(*v, ptr + "/x_axis");
      // Within 0.1° of towards_light the projection orthogonal to it is mostly rounding.
      if (glm::length(glm::cross(x, l.towards_light)) < 1.75e-3f)
        fail(ptr + "/x_axis", "must not be parallel to towards_light (it is the light's width direction across it)");
      l.x_axis = x;
    }
    return l;
  }

  // The probe's area lights (probe_directional_lights), appended to s.lights.
  void probe_lighting(const json& j, const std::string& ptr, Scene& s) const {
    keys(j, ptr, {"file", "lights", "intensity", "rotation_deg", "size", "horizon_split", "sub_lights"});
    ProbeLighting p;
    const json* file = find(j, "file");
    if (!file)
      fail(ptr + "/file", "required key missing (an equirectangular EXR or cube-map cross, six faces named by a "
                          "\"{face}\" path, or \"sky\")");
    const std::string name = string(*file, ptr + "/file");
    p.file = name == "sky" ? fs::path("sky") : probe_file(name, ptr + "/file");
    if (const json* v = find(j, "lights")) p.lights = integer(*v, ptr + "/lights");
    if (p.lights < 1 || p.lights > 256) fail(ptr + "/lights", "must be in [1, 256]");
    const std::size_t declared = s.lights.size() + s.local_lights.size();
    if (declared + std::size_t(p.lights) > std::size_t(kMaxLights))
      fail(ptr + "/lights",
           fmt::format("{} declared lights and {} of the probe exceed {} lights", declared, p.lights, kMaxLights));
    if (const json* v = find(j, "intensity")) p.intensity = number_in(*v, ptr + "/intensity", 0.0f, 1e6f, false, false);
    if (const json* v = find(j, "rotation_deg"))
      p.rotation_deg = number_in(*v, ptr + "/rotation_deg", -360.0f, 360.0f, false, false);
    if (const json* v = find(j, "size")) p.size = integer(*v, ptr + "/size");
    if (p.size < 1 || p.size > 1024) fail(ptr + "/size", "must be in [1, 1024]");
    if (const json* v = find(j, "horizon_split")) p.horizon_split = boolean(*v, ptr + "/horizon_split");
    if (const json* v = find(j, "sub_lights")) p.sub_lights = integer(*v, ptr + "/sub_lights");
    if (const std::string problem = sub_lights_problem(p); !problem.empty()) fail(ptr + "/sub_lights", problem);
    if (p.horizon_split) {
      try {
        msm::probe::check_cut(p.lights, p.size, true);
      } catch (const msm::probe::ProbeError& e) {
        fail(ptr + (p.lights < msm::probe::kHorizonSplitMinLights ? "/lights" : "/size"), e.what());
      }
    }
    p.first_light = s.lights.size();
    try {
      for (const DirectionalLight& l : probe_directional_lights(p)) s.lights.push_back(l);
    } catch (const msm::probe::ProbeError& e) { fail(ptr + "/file", e.what()); }
    if (s.lights.empty()) fail(ptr + "/file", "the probe has no light (every texel is black)");
    s.probe = p;
  }

  Medium medium(const json& j, const std::string& ptr) const {
    keys(j, ptr, {"extinction", "scattering_albedo", "phase", "g"});
    Medium m;
    const json* extinction = find(j, "extinction");
    if (!extinction) fail(ptr + "/extinction", "required key missing (the extinction coefficient σt, per scene unit)");
    m.extinction = number_in(*extinction, ptr + "/extinction", 0.0f, kMaxSize, true, false);
    if (const json* v = find(j, "scattering_albedo"))
      m.scattering_albedo = number_in(*v, ptr + "/scattering_albedo", 0.0f, 1.0f, false, false);
    const std::string phase = find(j, "phase") ? string(*find(j, "phase"), ptr + "/phase") : "isotropic";
    if (phase == "henyey_greenstein") {
      const json* g = find(j, "g");
      if (!g) fail(ptr + "/g", "required key missing (the Henyey-Greenstein asymmetry, in [-0.9999, 0.9999])");
      // |g| <= 0.9999: beyond it the phase function's peak is narrower than two float unit vectors
      // can resolve (scattering.h: 1 - cos θ from |u - v|² holds to about 3e-4 rad).
      m.g = number_in(*g, ptr + "/g", -0.9999f, 0.9999f, false, false);
    } else if (phase == "isotropic") {
      if (find(j, "g")) fail(ptr + "/g", "only allowed with \"phase\": \"henyey_greenstein\"");
    } else {
      fail(ptr + "/phase", fmt::format("unknown phase function \"{}\" (isotropic, henyey_greenstein)", phase));
    }
    return m;
  }

  ShadowFraming framing(const json& j, const std::string& ptr) const {
    keys(j, ptr, {"framing", "center", "extent", "depth_range"});
    ShadowFraming f;
    const std::string mode = find(j, "framing") ? string(*find(j, "framing"), ptr + "/framing") : "fit";
    if (mode == "fit" || mode == "fit_scene") {
      if (mode == "fit_scene") f.mode = ShadowFraming::Mode::fit_scene;
      for (const char* k : {"center", "extent", "depth_range"})
        if (find(j, k)) fail(ptr + "/" + k, "only allowed with \"framing\": \"explicit\"");
      return f;
    }
    if (mode != "explicit")
      fail(ptr + "/framing", fmt::format("unknown framing '{}' (fit, fit_scene, explicit)", mode));
    f.mode = ShadowFraming::Mode::given;
    for (const char* k : {"center", "extent", "depth_range"})
      if (!find(j, k)) fail(ptr + "/" + k, "required with \"framing\": \"explicit\"");
    f.center = vec<3>(*find(j, "center"), ptr + "/center");
    f.extent = vec<2>(*find(j, "extent"), ptr + "/extent");
    if (!(f.extent.x > 0.0f && f.extent.y > 0.0f)) fail(ptr + "/extent", "must be > 0");
    f.depth_range = vec<2>(*find(j, "depth_range"), ptr + "/depth_range");
    if (!(f.depth_range.y > f.depth_range.x)) fail(ptr + "/depth_range", "must be [near, far] with near < far");
    return f;
  }

  fs::path existing_file(const std::string& rel, const std::string& ptr, const char* what) const {
    if (rel.empty()) fail(ptr, "empty path");
    fs::path p = (base_ / fs::path(rel)).lexically_normal();
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      fail(ptr, fmt::format("{} file '{}' does not exist or is not a file", what, p.string()));
    return p;
  }

  // One EXR, or six face files named by a "{face}" path (msm::probe::probe_input_files), each there.
  fs::path probe_file(const std::string& rel, const std::string& ptr) const {
    for (const fs::path& file : msm::probe::probe_input_files(rel)) existing_file(file.string(), ptr, "light probe");
    return (base_ / fs::path(rel)).lexically_normal();
  }

  Material material(const json& j, const std::string& ptr) const {
    keys(j, ptr,
         {"albedo", "albedo_texture", "opacity", "opacity_texture", "opacity_noise", "transmission_color",
          "alpha_cutoff", "double_sided"});
    Material m;
    if (const json* v = find(j, "albedo")) {
      m.albedo = vec<3>(*v, ptr + "/albedo");
      if (glm::any(glm::lessThan(m.albedo, glm::vec3(0.0f))) || glm::any(glm::greaterThan(m.albedo, glm::vec3(1.0f))))
        fail(ptr + "/albedo", "components must be in [0, 1]");
    }
    if (const json* v = find(j, "albedo_texture"))
      m.albedo_texture = existing_file(string(*v, ptr + "/albedo_texture"), ptr + "/albedo_texture", "texture");
    if (const json* v = find(j, "opacity")) m.opacity = number_in(*v, ptr + "/opacity", 0.0f, 1.0f, false, false);
    if (const json* v = find(j, "opacity_texture"))
      m.opacity_texture = existing_file(string(*v, ptr + "/opacity_texture"), ptr + "/opacity_texture", "texture");
    if (const json* v = find(j, "opacity_noise")) {
      const std::string q = ptr + "/opacity_noise";
      if (!m.opacity_texture.empty()) fail(q, "give either opacity_texture or opacity_noise, not both");
      keys(*v, q, {"seed", "scale", "octaves", "density", "softness"});
      SmokeNoise n;
      if (const json* x = find(*v, "seed"))
        n.seed = std::uint32_t(number_in(*x, q + "/seed", 0.0f, 1e9f, false, false));
      if (const json* x = find(*v, "scale")) n.scale = number_in(*x, q + "/scale", 0.0f, 64.0f, true, false);
      if (const json* x = find(*v, "octaves")) n.octaves = int(number_in(*x, q + "/octaves", 1.0f, 8.0f, false, false));
      if (const json* x = find(*v, "density")) n.density = number_in(*x, q + "/density", 0.0f, 1.0f, false, false);
      if (const json* x = find(*v, "softness")) n.softness = number_in(*x, q + "/softness", 0.0f, 1.0f, true, false);
      m.opacity_noise = n;
    }
    if (const json* v = find(j, "transmission_color")) {
      const std::string q = ptr + "/transmission_color";
      if (!v->is_array() || v->size() != 3) fail(q, "must be an array of 3 numbers (r, g, b)");
      for (int c = 0; c < 3; ++c)
        m.transmission_color[c] = number_in((*v)[c], fmt::format("{}/{}", q, c), 0.0f, 1.0f, false, false);
    }
    if (const json* v = find(j, "alpha_cutoff")) {
      m.alpha_cutoff = number_in(*v, ptr + "/alpha_cutoff", 0.0f, 1.0f, false, false);
      if (glm::any(glm::greaterThan(m.transmission_color, glm::vec3(0.0f))))
        fail(ptr + "/alpha_cutoff", "an alpha-tested material is opaque: no transmission_color with it");
    }
    if (const json* v = find(j, "double_sided")) m.double_sided = boolean(*v, ptr + "/double_sided");
    return m;
  }

  // [x,y,z] with every |component| <= limit.
  glm::vec3 bounded(const json& v, const std::string& ptr, float limit, const char* what, const char* unit) const {
    const glm::vec3 x = vec<3>(v, ptr);
    if (glm::any(glm::greaterThan(glm::abs(x), glm::vec3(limit))))
      fail(ptr, fmt::format("absurd {} (|component| > {:g}{})", what, limit, unit));
    return x;
  }

  // {"axis": [x,y,z], "angle_deg": a}: the unit axis and the angle, in [lo, hi].
  std::pair<glm::vec3, float> axis_angle(const json& j, const std::string& ptr, float lo, float hi) const {
    keys(j, ptr, {"axis", "angle_deg"});
    if (!find(j, "axis") || !find(j, "angle_deg")) fail(ptr, "axis-angle needs \"axis\" and \"angle_deg\"");
    return {direction(*find(j, "axis"), ptr + "/axis"),
            number_in(*find(j, "angle_deg"), ptr + "/angle_deg", lo, hi, false, false)};
  }

  Transform transform(const json& j, const std::string& ptr) const {
    keys(j, ptr, {"translate", "rotate", "scale"});
    Transform t;
    if (const json* v = find(j, "translate"))
      t.translate = bounded(*v, ptr + "/translate", kMaxSize, "translation", "");
    if (const json* v = find(j, "rotate")) {
      glm::mat4 r(1.0f);
      if (v->is_array()) {
        const glm::vec3 e = glm::radians(vec<3>(*v, ptr + "/rotate"));
        r = glm::rotate(glm::mat4(1.0f), e.z, glm::vec3(0, 0, 1)) *
            glm::rotate(glm::mat4(1.0f), e.y, glm::vec3(0, 1, 0)) *
            glm::rotate(glm::mat4(1.0f), e.x, glm::vec3(1, 0, 0));
      } else if (v->is_object()) {
        const auto [axis, angle_deg] = axis_angle(*v, ptr + "/rotate", -3e38f, 3e38f);
        r = glm::rotate(glm::mat4(1.0f), glm::radians(angle_deg), axis);
      } else {
        fail(ptr + "/rotate", "must be Euler degrees [x,y,z] or {\"axis\": [x,y,z], \"angle_deg\": a}");
      }
      t.rotate = glm::mat3(r);
    }
    if (const json* v = find(j, "scale")) {
      t.scale = v->is_array() ? vec<3>(*v, ptr + "/scale") : glm::vec3(number(*v, ptr + "/scale"));
      for (int i = 0; i < 3; ++i)
        if (!(t.scale[i] > 0.0f) || t.scale[i] > kMaxSize)
          fail(ptr + "/scale",
               fmt::format("must be > 0 and <= {:g} (got {:g}); mirroring is not supported", kMaxSize, t.scale[i]));
    }
    return t;
  }

  Motion motion(const json& j, const std::string& ptr) const {
    if (!j.is_object()) fail(ptr, "must be an object with \"translate\" and/or \"rotate\" (per frame)");
    keys(j, ptr, {"translate", "rotate"});
    Motion m;
    if (const json* v = find(j, "translate"))
      m.translate = bounded(*v, ptr + "/translate", kMaxMotionPerFrame, "motion", " per frame");
    if (const json* v = find(j, "rotate")) {
      if (!v->is_object()) fail(ptr + "/rotate", "must be {\"axis\": [x,y,z], \"angle_deg\": a} (per frame)");
      std::tie(m.axis, m.angle_deg) = axis_angle(*v, ptr + "/rotate", -360.0f, 360.0f);
    }
    if (!find(j, "translate") && !find(j, "rotate")) fail(ptr, "needs \"translate\" and/or \"rotate\" (per frame)");
    return m;
  }

  Mesh primitive(const json& j, const std::string& ptr, std::string& type) const {
    if (!j.is_object()) fail(ptr, "must be an object with a \"type\"");
    const json* tj = find(j, "type");
    if (!tj)
      fail(ptr + "/type", "required key missing (plane, box, sphere, cylinder, fence, stair, torus_knot, brick_wall)");
    type = string(*tj, ptr + "/type");
    auto num = [&](const char* k, float def) {
      const json* v = find(j, k);
      return v ? number(*v, ptr + "/" + k) : def;
    };
    auto intg = [&](const char* k, int def) {
      const json* v = find(j, k);
      return v ? integer(*v, ptr + "/" + k) : def;
    };
    try {
      if (type == "plane") {
        keys(j, ptr, {"type", "size", "subdivisions"});
        const glm::vec2 size = find(j, "size") ? vec<2>(*find(j, "size"), ptr + "/size") : glm::vec2(10.0f);
        glm::ivec2 sub(1);
        if (const json* v = find(j, "subdivisions")) {
          if (!v->is_array() || v->size() != 2) fail(ptr + "/subdivisions", "must be an array of 2 integers");
          sub = {integer((*v)[0], ptr + "/subdivisions/0"), integer((*v)[1], ptr + "/subdivisions/1")};
        }
        return make_plane(size, sub);
      }
      if (type == "box") {
        keys(j, ptr, {"type", "size"});
        return make_box(find(j, "size") ? vec<3>(*find(j, "size"), ptr + "/size") : glm::vec3(1.0f));
      }
      if (type == "sphere") {
        keys(j, ptr, {"type", "radius", "segments", "rings"});
        return make_sphere(num("radius", 0.5f), intg("segments", 64), intg("rings", 32));
      }
      if (type == "cylinder") {
        keys(j, ptr, {"type", "radius", "height", "segments", "caps"});
        const bool caps = find(j, "caps") ? boolean(*find(j, "caps"), ptr + "/caps") : true;
        return make_cylinder(num("radius", 0.5f), num("height", 1.0f), intg("segments", 64), caps);
      }
      if (type == "fence") {
        keys(j, ptr, {"type", "length", "height", "bars", "bar_width", "bar_depth", "rails", "rail_height"});
        return make_fence(num("length", 4.0f), num("height", 1.0f), intg("bars", 9), num("bar_width", 0.05f),
                          num("bar_depth", 0.05f), intg("rails", 2), num("rail_height", 0.05f));
      }
      if (type == "stair") {
        keys(j, ptr, {"type", "steps", "width", "step_depth", "step_height"});
        return make_stair(intg("steps", 5), num("width", 2.0f), num("step_depth", 0.3f), num("step_height", 0.2f));
      }
      if (type == "torus_knot") {
        keys(j, ptr, {"type", "p", "q", "radius", "tube_radius", "segments", "tube_segments"});
        return make_torus_knot(intg("p", 2), intg("q", 3), num("radius", 1.0f), num("tube_radius", 0.15f),
                               intg("segments", 256), intg("tube_segments", 16));
      }
      if (type == "brick_wall") {
        keys(j, ptr, {"type", "rows", "columns", "brick_length", "brick_height", "mortar", "relief", "thickness"});
        return make_brick_wall(intg("rows", 12), intg("columns", 8), num("brick_length", 0.24f),
                               num("brick_height", 0.07f), num("mortar", 0.012f), num("relief", 0.02f),
                               num("thickness", 0.2f));
      }
    } catch (const SceneError& e) {
      if (!e.file().empty()) throw; // already complete (from this parser)
      fail(e.where().empty() ? ptr : ptr + "/" + e.where(), e.problem());
    }
    fail(ptr + "/type",
         fmt::format("unknown primitive '{}' (plane, box, sphere, cylinder, fence, stair, torus_knot, brick_wall)",
                     type));
  }

  // One JSON object: one Object, or for a mesh file with several materials and no "material"
  // key one Object per material of the file ("<name>/<material>").
  void object(const json& j, const std::string& ptr, std::size_t index, Scene& s) const {
    std::string name = fmt::format("object{}", index);
    if (j.is_object())
      if (const json* v = find(j, "name")) name = this->name(*v, ptr + "/name");
    try {
      keys(j, ptr, {"name", "mesh", "primitive", "transform", "material", "motion", "import_lights"});
      const json* mesh = find(j, "mesh");
      const json* prim = find(j, "primitive");
      if (!mesh == !prim) fail(ptr, "needs exactly one of \"mesh\" (a file) and \"primitive\"");
      Object o;
      o.name = name;
      if (const json* v = find(j, "transform")) o.transform = transform(*v, ptr + "/transform");
      if (const json* v = find(j, "motion")) o.motion = motion(*v, ptr + "/motion");
      const json* material_json = find(j, "material");
      if (material_json) {
        if (material_json->is_string()) {
          const auto it = named_.find(material_json->get<std::string>());
          if (it == named_.end())
            fail(ptr + "/material", fmt::format("unknown material '{}'", material_json->get<std::string>()));
          o.material = it->second;
        } else {
          o.material = static_cast<std::uint32_t>(s.materials.size());
          s.materials.push_back(material(*material_json, ptr + "/material"));
        }
      }
      if (!mesh) {
        if (find(j, "import_lights")) fail(ptr + "/import_lights", "imports a glTF \"mesh\" file's lights");
        Mesh m = primitive(*prim, ptr + "/primitive", o.primitive);
        add_object(std::move(o), std::move(m), ptr, s);
        return;
      }
      o.mesh_file = existing_file(string(*mesh, ptr + "/mesh"), ptr + "/mesh", "mesh");
      if (const json* v = find(j, "import_lights"); v && boolean(*v, ptr + "/import_lights")) {
        if (o.motion)
          fail(ptr + "/import_lights", "an animated object's lights are not imported (they would stay put)");
        import_lights(o.mesh_file, o.transform, ptr + "/import_lights", s);
      }
      std::vector<ModelPart> parts;
      try {
        if (material_json) {
          parts.push_back({"", import_mesh(o.mesh_file), std::nullopt});
        } else {
          parts = import_model(o.mesh_file);
        }
      } catch (const SceneError& e) { fail(ptr + "/mesh", fmt::format("{} ({})", e.problem(), o.mesh_file.string())); }
      for (ModelPart& part : parts) {
        Object p = o;
        if (parts.size() > 1) p.name = fmt::format("{}/{}", name, part.name);
        if (part.material) {
          p.material = static_cast<std::uint32_t>(s.materials.size());
          s.materials.push_back(std::move(*part.material));
          s.materials.back().name = fmt::format("{}/{}", name, s.materials.back().name);
        }
        add_object(std::move(p), std::move(part.mesh), ptr, s);
      }
    } catch (const SceneError& e) {
      // Name the object in the location.
      throw SceneError(e.file(), fmt::format("{} (object '{}')", e.where(), name), e.problem());
    }
  }

  // To world space. Scale > 0, so the winding is kept; normals by the inverse transpose.
  void add_object(Object o, Mesh m, const std::string& ptr, Scene& s) const {
    const glm::mat4 mm = o.transform.matrix();
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      m.positions[v] = glm::vec3(mm * glm::vec4(m.positions[v], 1.0f));
      m.normals[v] = glm::normalize(o.transform.rotate * (m.normals[v] / o.transform.scale));
    }
    try {
      detail::finalize_mesh(m, "");
    } catch (const SceneError& e) { fail(ptr, "after the transform: " + e.problem()); }
    // The scene's running total against the limit (msm/util/limits.h), object by object: 40
    // spheres of 4M triangles stop at the limit, not in std::bad_alloc after gigabytes.
    triangles_ += m.triangle_count();
    if (triangles_ > limits::max_triangles())
      fail(ptr, fmt::format("the scene has {} triangles up to this object; the limit is {} (MSM_MAX_TRIANGLES "
                            "raises it)",
                            limits::with_commas(triangles_), limits::with_commas(limits::max_triangles())));
    o.mesh = std::move(m);
    o.bounds = o.mesh.bounds();
    s.objects.push_back(std::move(o));
  }

  std::string file_;
  fs::path base_;
  mutable std::uint64_t triangles_ = 0; // of the objects added so far
  std::map<std::string, std::uint32_t> named_;
};

} // namespace

std::span<const LightKindInfo> light_kinds() { return kLightKinds; }

const LightKindInfo& light_kind(LightKind kind) {
  for (const LightKindInfo& k : kLightKinds)
    if (k.kind == kind) return k;
  throw std::invalid_argument("undeclared light kind");
}

std::optional<LightKind> parse_light_kind(std::string_view name) {
  for (const LightKindInfo& k : kLightKinds)
    if (k.name == name) return k.kind;
  return std::nullopt;
}

float LocalLight::cos_outer() const { return spot() ? std::cos(glm::radians(outer_cone_deg)) : -1.0f; }
float LocalLight::cos_inner() const { return spot() ? std::cos(glm::radians(inner_cone_deg)) : -1.0f; }

glm::vec3 LocalLight::irradiance_at(const glm::vec3& p) const {
  const glm::vec3 from_light = p - position;
  const float distance = glm::length(from_light);
  const float cos_angle = distance > 0.0f ? glm::dot(from_light, direction) / distance : 1.0f;
  return msm::msm_local_light_irradiance(intensity, distance, range, cos_angle, cos_outer(), cos_inner());
}

std::size_t Scene::light_count(LightKind kind) const {
  if (kind == LightKind::directional) return lights.size();
  return std::size_t(
      std::count_if(local_lights.begin(), local_lights.end(), [&](const LocalLight& l) { return l.kind == kind; }));
}

DirectionalLight light_of_probe_light(const msm::probe::ProbeLight& light) {
  DirectionalLight l = light_of_area_light(light.light);
  for (const msm::MsmAreaLight& a : light.sub_lights) l.sub_lights.push_back(light_of_area_light(a));
  return l;
}

SubLightsLinearPart sub_lights_linear_part(const DirectionalLight& light) {
  SubLightsLinearPart part;
  if (light.sub_lights.empty()) return part;
  const glm::vec3 l = light.towards_light;
  // The light frame's x axis as the shading takes it (msm_rect_light_cosine), else any.
  glm::vec3 x = light.x_axis.value_or(glm::vec3(0.0f));
  x -= l * glm::dot(x, l);
  part.x_axis = glm::length(x) > 1e-6f ? glm::normalize(x) : msm::msm_perpendicular(l);
  part.y_axis = glm::cross(l, part.x_axis);
  part.bounds = glm::vec2(0.0f);
  for (const DirectionalLight& sub : light.sub_lights) {
    part.irradiance_by_direction += glm::outerProduct(sub.irradiance, sub.towards_light);
    const glm::vec2 b = msm::msm_light_tangent_bounds(l, part.x_axis, part.y_axis, sub.towards_light,
                                                      sub.x_axis.value_or(glm::vec3(0.0f)), sub.rectangle_extents(),
                                                      sub.cone_half_angle());
    part.bounds = (b.x < 0.0f || part.bounds.x < 0.0f) ? glm::vec2(-1.0f) : glm::max(part.bounds, b);
  }
  return part;
}

DirectionalLight light_of_area_light(const msm::MsmAreaLight& area) {
  DirectionalLight l;
  l.towards_light = area.direction;
  l.x_axis = area.x_axis;
  l.angular_extent_deg = std::min(2.0f * glm::degrees(std::atan(area.half_extent.x)), 89.0f);
  l.angular_height_deg = std::min(2.0f * glm::degrees(std::atan(area.half_extent.y)), 89.0f);
  // Eq. 18 for the rectangle that is drawn (the extents kept below 90°): M_e F / Ω.
  l.irradiance = area.irradiance * msm::msm_rect_light_facing_fraction(l.tan_half_extents());
  return l;
}

DirectionalLight overridden_light(DirectionalLight light, std::optional<float> extent_deg,
                                  std::optional<float> height_deg) {
  if (extent_deg) {
    light.angular_extent_deg = *extent_deg;
    light.angular_height_deg.reset();
  }
  if (height_deg) light.angular_height_deg = *height_deg;
  return light;
}

glm::vec2 DirectionalLight::tan_half_extents() const {
  const auto half_tan = [](float deg) { return std::tan(glm::radians(deg) * 0.5f); };
  return {half_tan(angular_extent_deg), half_tan(angular_height_deg.value_or(angular_extent_deg))};
}

float DirectionalLight::cone_half_angle() const {
  return rectangular() ? msm::msm_rect_light_cone_half_angle(tan_half_extents())
                       : glm::radians(angular_extent_deg) * 0.5f;
}

SceneError::SceneError(std::string file, std::string where, std::string problem)
    : std::runtime_error(compose(file, where, problem)), file_(std::move(file)), where_(std::move(where)),
      problem_(std::move(problem)) {}

glm::mat4 Transform::matrix() const {
  return glm::translate(glm::mat4(1.0f), translate) * glm::mat4(rotate) * glm::scale(glm::mat4(1.0f), scale);
}

glm::mat4 Camera::view() const { return glm::lookAtRH(position, target, up); }

glm::mat4 Camera::projection(float aspect) const {
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) throw SceneError("", "aspect", "must be finite and > 0");
  return flip_y(glm::perspectiveRH_ZO(glm::radians(fov_y_deg), aspect, near, far));
}

Bounds Scene::bounds() const {
  Bounds b;
  for (const Object& o : objects) b.extend(o.bounds);
  return b;
}

bool Scene::animated() const {
  return std::ranges::any_of(objects, [](const Object& o) { return o.motion.has_value(); });
}

Scene at_frame(const Scene& scene, int frame) {
  if (frame < 0) throw SceneError(scene.source.string(), "", fmt::format("frame {}: must be >= 0", frame));
  Scene out = scene;
  for (Object& o : out.objects) {
    if (!o.motion || frame == 0) continue;
    // In double: frame × angle stays exact to far more frames than the CLI allows.
    const double angle = glm::radians(double(frame) * double(o.motion->angle_deg));
    const glm::mat3 turn(glm::rotate(glm::dmat4(1.0), angle, glm::dvec3(o.motion->axis)));
    const glm::vec3 origin = o.transform.translate;
    const glm::vec3 moved = origin + float(frame) * o.motion->translate;
    for (glm::vec3& p : o.mesh.positions) p = moved + turn * (p - origin);
    for (glm::vec3& n : o.mesh.normals) n = glm::normalize(turn * n);
    o.transform.translate = moved;
    o.transform.rotate = turn * o.transform.rotate;
    o.bounds = o.mesh.bounds();
  }
  return out;
}

std::size_t Scene::triangle_count() const {
  std::size_t n = 0;
  for (const Object& o : objects) n += o.mesh.triangle_count();
  return n;
}

std::size_t Scene::vertex_count() const {
  std::size_t n = 0;
  for (const Object& o : objects) n += o.mesh.positions.size();
  return n;
}

glm::mat4 Scene::light_view(const DirectionalLight& light) const {
  const glm::vec3 d = light.travel();
  glm::vec3 up = std::abs(d.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  // The light's own x axis (its width's direction, Kneiphof §4.1.2): lookAt's first axis is
  // normalize(cross(d, up)), which is x projected orthogonal to d for up = cross(x, d).
  if (light.x_axis) {
    const glm::vec3 x_up = glm::cross(*light.x_axis, d);
    if (glm::length(x_up) > 1e-3f * glm::length(*light.x_axis)) up = glm::normalize(x_up);
  }
  const Bounds b = bounds();
  const glm::vec3 c =
      shadow.mode == ShadowFraming::Mode::given ? shadow.center : (b.empty() ? glm::vec3(0.0f) : b.center());
  return glm::lookAtRH(c, c + d, up);
}

glm::mat4 Scene::light_projection(const DirectionalLight& light) const {
  if (shadow.mode == ShadowFraming::Mode::given) {
    const glm::vec2 h = 0.5f * shadow.extent;
    return flip_y(glm::orthoRH_ZO(-h.x, h.x, -h.y, h.y, shadow.depth_range.x, shadow.depth_range.y));
  }
  const LightBox b = fit_light_frustum(*this, light_view(light), shadow.mode == ShadowFraming::Mode::fit);
  // View space looks down -z: distance along the light's travel is -z.
  return flip_y(glm::orthoRH_ZO(b.lo.x, b.hi.x, b.lo.y, b.hi.y, -b.hi.z, -b.lo.z));
}

LightFrame Scene::light_frame(const DirectionalLight& light) const {
  return orthographic_light_frame(light_projection(light) * light_view(light), light.towards_light);
}

Scene load_scene_json(std::string_view json_text, const std::filesystem::path& base_dir,
                      const std::string& source_name) {
  return Parser(source_name, base_dir).parse(json_text);
}

DeclaredLight parse_light(std::string_view json_text, const std::string& source, const std::string& where) {
  return Parser(source, {}).parse_light(json_text, where);
}

Scene load_scene_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw SceneError(file.string(), "", "scene file does not exist");
  if (!std::filesystem::is_regular_file(file, ec))
    throw SceneError(file.string(), "", "scene path is not a regular file");
  const auto size = std::filesystem::file_size(file, ec);
  if (ec || size > (64u << 20)) throw SceneError(file.string(), "", "scene file unreadable or larger than 64 MiB");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SceneError(file.string(), "", "cannot open the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  Scene s = load_scene_json(text.str(), file.parent_path(), file.string());
  s.source = file;
  if (s.name.empty()) s.name = file.stem().string(); // outputs and messages name every scene
  return s;
}

std::vector<std::string> builtin_scene_names() {
  std::vector<std::string> names;
  for (const BuiltinScene& b : kBuiltinScenes) names.emplace_back(b.name);
  return names;
}

std::string_view default_scene_name() { return "fence"; }

std::string_view builtin_scene_json(std::string_view name) {
  for (const BuiltinScene& b : kBuiltinScenes)
    if (b.name == name) return b.json;
  throw SceneError(
      "", "", fmt::format("unknown built-in scene '{}' (known: {})", name, fmt::join(builtin_scene_names(), ", ")));
}

Scene builtin_scene(std::string_view name) {
  const std::string source = fmt::format("builtin:{}", name);
  return load_scene_json(builtin_scene_json(name), std::filesystem::path("."), source);
}

void set_probe_light_count(Scene& scene, int count, std::optional<int> sub_lights) {
  const std::string file = scene.source.string();
  if (!scene.probe) throw SceneError(file, "/probe", "the scene has no probe, so no probe lights to count");
  ProbeLighting p = *scene.probe;
  if (count < 1 || count > 256)
    throw SceneError(file, "/probe/lights", fmt::format("{} lights: must be in [1, 256]", count));
  const std::size_t old_end = std::min(scene.lights.size(), p.first_light + std::size_t(p.lights));
  const std::size_t others = scene.lights.size() - (old_end - p.first_light) + scene.local_lights.size();
  if (others + std::size_t(count) > std::size_t(kMaxLights))
    throw SceneError(file, "/probe/lights",
                     fmt::format("{} declared lights and {} of the probe exceed {} lights", others, count, kMaxLights));
  p.lights = count;
  try {
    msm::probe::check_cut(count, p.size, p.horizon_split);
  } catch (const msm::probe::ProbeError& e) { throw SceneError(file, "/probe/lights", e.what()); }
  if (sub_lights) {
    p.sub_lights = *sub_lights;
    if (const std::string problem = sub_lights_problem(p); !problem.empty())
      throw SceneError(file, "/probe/sub_lights", problem);
  }
  std::vector<DirectionalLight> lights;
  try {
    lights = probe_directional_lights(p);
  } catch (const msm::probe::ProbeError& e) { throw SceneError(file, "/probe/file", e.what()); }
  if (lights.empty() && others == 0)
    throw SceneError(file, "/probe/file", "the probe has no light (every texel is black)");
  scene.lights.erase(scene.lights.begin() + std::ptrdiff_t(p.first_light),
                     scene.lights.begin() + std::ptrdiff_t(old_end));
  scene.lights.insert(scene.lights.begin() + std::ptrdiff_t(p.first_light), lights.begin(), lights.end());
  scene.probe = p;
}

void set_probe(Scene& scene, const std::filesystem::path& file) {
  ProbeLighting p = scene.probe.value_or(ProbeLighting{});
  p.file = file;
  p.first_light = 0;
  std::error_code ec;
  if (file != "sky")
    for (const std::filesystem::path& f : msm::probe::probe_input_files(file))
      if (!std::filesystem::is_regular_file(f, ec))
        throw SceneError(f.string(), "",
                         "no such light probe (an equirectangular EXR, a cube-map cross, six faces named by a "
                         "\"{face}\" path, or \"sky\")");
  std::vector<DirectionalLight> lights;
  try {
    lights = probe_directional_lights(p);
  } catch (const msm::probe::ProbeError& e) {
    // A cross or six faces cannot turn: say where the turn comes from.
    throw SceneError("", "",
                     p.rotation_deg == 0.0f
                         ? std::string(e.what())
                         : fmt::format("{} (the scene's probe has \"rotation_deg\": {:g})", e.what(), p.rotation_deg));
  }
  if (lights.empty()) throw SceneError(file.string(), "", "the probe has no light (every texel is black)");
  scene.lights = std::move(lights);
  scene.local_lights.clear();
  scene.probe = p;
}

Scene load_scene(std::string_view name_or_path) {
  for (const BuiltinScene& b : kBuiltinScenes)
    if (b.name == name_or_path) return builtin_scene(name_or_path);
  const std::filesystem::path p{std::string(name_or_path)};
  std::error_code ec;
  if (!std::filesystem::exists(p, ec))
    throw SceneError(std::string(name_or_path), "",
                     fmt::format("neither a built-in scene ({}) nor an existing scene file",
                                 fmt::join(builtin_scene_names(), ", ")));
  return load_scene_file(p);
}

} // namespace msm::scene
