// View files and viewer scripts without a window: a view comes back from its JSON exactly (the
// screenshot test relies on that), and every kind of bad input names the key or the line.
#include "msm/viewer/script.h"
#include "msm/viewer/view_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

namespace msm::viewer {
namespace {

// The message of the ViewError / ScriptError that f throws ("" if none).
template <class Error, class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const Error& e) { return e.what(); }
  return "";
}

TEST(ViewFile, RoundTripIsExact) {
  View v;
  v.scene = "railing";
  scene::Camera c;
  c.position = {1.0f / 3.0f, 2.2f, -5.7f};
  c.target = {0.1f, 0.2f, 0.3f};
  c.fov_y_deg = 37.5f;
  c.near = 0.05f;
  c.far = 321.0f;
  v.camera = c;
  scene::DirectionalLight l;
  l.towards_light = glm::normalize(glm::vec3(0.3f, 0.9f, 0.1f));
  l.irradiance = {1.0f, 2.0f, 3.0f};
  v.settings.lights = {l};
  render::RenderSettings& s = v.settings;
  s.technique = "vsm-32";
  s.width = 333;
  s.height = 222;
  s.shadow_size = 512;
  s.msaa = 1;
  s.filter_size = 5;
  s.filter_sigma = 1.7f;
  s.mipmaps = false;
  s.parameters = {{"min_variance", 1e-7f}};
  s.depth_bias = 3e-5f;
  s.lookup = render::RenderSettings::Lookup::nearest;
  s.one_pass = false;
  s.frame = 7;
  s.coloured_translucency = true;
  s.light_extent_deg = 2.5f;
  s.light_height_deg = 1.25f;
  s.soft_kernel = 11;

  nlohmann::json j = view_json(v);
  View back = parse_view(j.dump(2), "v.json");
  EXPECT_EQ(view_json(back), j);
  ASSERT_TRUE(back.camera);
  EXPECT_EQ(back.camera->position, c.position); // bit-identical floats, not close ones
  EXPECT_EQ(back.camera->near, c.near);
  EXPECT_EQ(back.settings.lights.at(0).towards_light, l.towards_light);
  EXPECT_EQ(back.settings.parameters, s.parameters);
  EXPECT_EQ(j["settings"]["parameters"].size(), 1u); // by name
  EXPECT_EQ(j["settings"]["parameters"]["min_variance"].get<float>(), 1e-7f);
  EXPECT_EQ(*back.settings.depth_bias, *s.depth_bias);
  EXPECT_EQ(back.settings.lookup, s.lookup);
  EXPECT_EQ(back.settings.one_pass, s.one_pass);
  EXPECT_EQ(back.settings.filter_sigma, s.filter_sigma);
  EXPECT_EQ(back.settings.light_height_deg, s.light_height_deg);
}

TEST(ViewFile, DefaultsStayDefaults) {
  View v = parse_view(R"({"msm_view": 1})", "v.json");
  EXPECT_EQ(v.scene, "fence");
  EXPECT_FALSE(v.camera); // the scene's
  EXPECT_TRUE(v.settings.lights.empty());
  EXPECT_TRUE(v.settings.parameters.empty());
  EXPECT_FALSE(v.settings.depth_bias);
  EXPECT_FALSE(v.settings.light_extent_deg);
  EXPECT_FALSE(v.settings.light_height_deg);
  EXPECT_FALSE(v.settings.front_back_depth);
}

// front_back_depth (Kneiphof §4.2.3, RenderSettings::front_back_depth): written, read back, off by
// default, a boolean, and refused with a technique that does not take it (a soft one only).
TEST(ViewFile, FrontBackDepthRoundTripsAndIsValidated) {
  View v;
  v.settings.technique = "mssm4";
  v.settings.front_back_depth = true;
  nlohmann::json j = view_json(v);
  EXPECT_EQ(j["settings"]["front_back_depth"], true);
  View back = parse_view(j.dump(2), "v.json");
  EXPECT_TRUE(back.settings.front_back_depth);
  EXPECT_EQ(view_json(back), j);
  v.settings.front_back_depth = false;
  EXPECT_FALSE(parse_view(view_json(v).dump(), "v.json").settings.front_back_depth);
  EXPECT_FALSE(
      parse_view(R"({"msm_view": 1, "settings": {"technique": "mssm6"}})", "v.json").settings.front_back_depth);
  EXPECT_TRUE(parse_view(R"({"msm_view": 1, "settings": {"technique": "cssm16", "front_back_depth": true}})", "v.json")
                  .settings.front_back_depth);

  auto bad = [](const std::string& text) { return error_of<ViewError>([&] { parse_view(text, "v.json"); }); };
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"technique": "mssm4", "front_back_depth": 1}})")
                .find("v.json: /settings/front_back_depth: expected true or false, got 1"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"technique": "pcf", "front_back_depth": true}})")
                .find("v.json: /settings: front-and-back-face depth applies to the moment soft shadows"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"front_back_dept": true}})")
                .find("/settings/front_back_dept: unknown setting (did you mean front_back_depth"),
            std::string::npos);
}

// The animated objects' frame: round trip, absent at 0, its range; load_view_scene moves the
// objects (the knot of city_probe turns 10° a frame).
TEST(ViewFile, ObjectFrameRoundTripsAndIsValidated) {
  View v;
  v.scene = "city_probe";
  EXPECT_FALSE(view_json(v).contains("object_frame"));
  v.object_frame = 3;
  const nlohmann::json j = view_json(v);
  EXPECT_EQ(j["object_frame"], 3);
  EXPECT_EQ(parse_view(j.dump(), "v.json").object_frame, 3);
  const scene::Scene at3 = load_view_scene(v), at0 = scene::load_scene("city_probe");
  EXPECT_EQ(at3.objects.back().mesh.positions, scene::at_frame(at0, 3).objects.back().mesh.positions);
  EXPECT_NE(at3.objects.back().mesh.positions, at0.objects.back().mesh.positions);
  auto bad = [](const std::string& text) { return error_of<ViewError>([&] { parse_view(text, "v.json"); }); };
  EXPECT_NE(bad(R"({"msm_view": 1, "object_frame": -1})").find("v.json: /object_frame: expected 0 to 100000"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "object_frame": 2.5})").find("/object_frame: expected an integer"),
            std::string::npos);
}

TEST(ViewFile, RelativeScenePathsFollowTheFile) {
  View v = parse_view(R"({"msm_view": 1, "scene": "my/scene.json"})", "/data/views/v.json");
  EXPECT_EQ(v.scene, "/data/views/my/scene.json");
  EXPECT_EQ(parse_view(R"({"msm_view": 1, "scene": "glass"})", "/data/v.json").scene, "glass");
}

TEST(ViewFile, BadInputNamesTheKey) {
  auto bad = [](const std::string& text) { return error_of<ViewError>([&] { parse_view(text, "v.json"); }); };
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"filter_sise": 5}})")
                .find("v.json: /settings/filter_sise: unknown setting (did you mean filter_size"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"msaa": "four"}})").find("/settings/msaa: expected an integer"),
            std::string::npos);
  // Parameters by name, validated against the technique's declarations whatever the keys' order.
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"parameters": {"betta": "fixed"}, "technique": "scatter-msm6-96"}})")
                .find("v.json: /settings/parameters/betta: unknown parameter 'betta' of scatter-msm6-96 (did you "
                      "mean beta?)"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"technique": "msm", "parameters": {"moment_bias": -1}}})")
                .find("/settings/parameters/moment_bias: moment_bias = '-1' is outside [0, 1]"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"params": [0, 0, 0, 0]}})")
                .find("/settings/params: replaced by \"parameters\", each by name (msm techniques NAME lists them)"),
            std::string::npos);
  View named = parse_view(
      R"({"msm_view": 1, "settings": {"parameters": {"beta": "adaptive", "layers": 4}, "technique": "scatter-msm6-96"}})",
      "v.json");
  EXPECT_EQ(named.settings.parameter_text("beta"), "adaptive");
  EXPECT_EQ(named.settings.parameter("layers"), 4.0f);
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"technique": "nope"}})").find("unknown technique 'nope'"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "settings": {"filter_size": 8}})").find("filter size = 8 must be odd"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "camera": {"positon": [0, 1, 2]}})").find("/camera/positon: unknown key"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "camera": {"position": [0, 1]}})").find("/camera/position: expected [x, y, z]"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "camera": {"position": [0, 0, 0], "target": [0, 0, 0]}})")
                .find("/camera/target: equals the position"),
            std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1, "lights": [{"towards_light": [0, 0, 0]}]})").find("/lights/0/towards_light"),
            std::string::npos);
  EXPECT_NE(bad(R"({"settings": {}})").find("/msm_view: required"), std::string::npos);
  EXPECT_NE(bad(R"({"msm_view": 1,)").find("v.json: malformed JSON"), std::string::npos);
  EXPECT_NE(error_of<ViewError>([] { load_view("/nonexistent/v.json"); }).find("cannot open the view file"),
            std::string::npos);
}

TEST(ViewFile, SaveIsAtomicAndLoadsBack) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / "msm_view_file_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  View v;
  v.settings.technique = "pcf";
  save_view(dir / "v.json", v);
  EXPECT_EQ(load_view(dir / "v.json").settings.technique, "pcf");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1); // no temporary left behind
  EXPECT_NE(error_of<ViewError>([&] { save_view(dir / "missing" / "v.json", v); }).find("cannot write"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(Script, ParsesActionsAndComments) {
  std::vector<Action> a =
      parse_script("# comment\n\ntechnique msm  # trailing\nset parameters {\"moment_bias\": 3e-5}\n"
                   "set lookup nearest\nresize 640 360\nquit\n",
                   "s.txt");
  ASSERT_EQ(a.size(), 5u);
  EXPECT_EQ(a[0].verb, "technique");
  EXPECT_EQ(a[0].line, 3);
  EXPECT_EQ(a[1].args.at(1), "{\"moment_bias\": 3e-5}"); // the rest of the line
  EXPECT_EQ(setting_value(a[2].args.at(1)), "nearest");
  EXPECT_EQ(a[4].where, "s.txt:7");
}

TEST(Script, BadLinesAreNamed) {
  auto bad = [](const std::string& text) { return error_of<ScriptError>([&] { parse_script(text, "s.txt"); }); };
  EXPECT_EQ(bad("quit\nscreenshto a.png\n"), "s.txt:2: unknown action 'screenshto' (did you mean screenshot?)");
  EXPECT_EQ(bad("technique\n"), "s.txt:1: technique takes 1 argument, got 0");
  EXPECT_NE(bad("technique nope\n").find("s.txt:1: unknown technique 'nope'"), std::string::npos);
  EXPECT_NE(bad("frames 1\nset msaa [4]\n").find("s.txt:2: set msaa: expected an integer"), std::string::npos);
  EXPECT_EQ(bad("camera 0 1 2 3 4 x\n"), "s.txt:1: 'x' is not a number");
  EXPECT_EQ(bad("resize 10 10\n"), "s.txt:1: resize 10 10: sizes are integers in [64, 8192]");
  EXPECT_EQ(bad("divider 1.5\n"), "s.txt:1: divider 1.5 is outside (0, 1)");
  EXPECT_EQ(bad("object-frame -2\n"), "s.txt:1: object-frame -2: expected an integer in [0, 100000]");
  EXPECT_EQ(bad("panel closed\n"), "s.txt:1: panel closed: open or collapsed");
  EXPECT_NE(error_of<ScriptError>([] { load_script("/nonexistent/s.txt"); }).find("cannot open the script"),
            std::string::npos);
}

TEST(Script, LightActions) {
  std::vector<Action> a = parse_script("light-add spot\nlight-move 1 0 2.5 0\nlight-set 1 intensity [5, 5, 5]\n"
                                       "light-off 0\nlight-on 0\nlight-remove 1\n",
                                       "s.txt");
  ASSERT_EQ(a.size(), 6u);
  EXPECT_EQ(a[2].args, (std::vector<std::string>{"1", "intensity", "[5, 5, 5]"})); // the value: the rest
  EXPECT_EQ(setting_value(a[2].args[2]), nlohmann::json::array({5, 5, 5}));
  auto bad = [](const std::string& text) { return error_of<ScriptError>([&] { parse_script(text, "s.txt"); }); };
  EXPECT_EQ(bad("light-add spto\n"), "s.txt:1: light-add spto: unknown kind of light (did you mean spot?)");
  EXPECT_EQ(bad("light-set 0 outer_cone\n"), "s.txt:1: light-set takes 3 arguments, got 2");
  EXPECT_EQ(bad("light-set 0 outer_cone 40\n"),
            "s.txt:1: light-set outer_cone: no kind of light has this key (did you mean outer_cone_deg?)");
  EXPECT_EQ(bad("light-off -1\n"), "s.txt:1: light-off -1: a light's number, an integer in [0, 255]");
  EXPECT_EQ(bad("light-move 0 1 2 z\n"), "s.txt:1: 'z' is not a number");
}

} // namespace
} // namespace msm::viewer
