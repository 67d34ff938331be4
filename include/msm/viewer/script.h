// The viewer's scripts (`msm view --script FILE`): one action per line, run one per frame through
// the same code paths the panel calls. `#` starts a comment; blank lines are skipped.
//
//   technique NAME            select a technique (or alias) of the technique table
//   each-technique            every technique of the table in turn, one frame each
//   set KEY VALUE             a render setting of the view file (view_file.h: setting_keys()); VALUE
//                             is JSON (5, 0.1, true, [0,0,0,3e-5], null) or a bare word ("nearest")
//   scene NAME|FILE           another scene (its camera and lights)
//   reload                    the scene file again (the view kept)
//   camera PX PY PZ TX TY TZ  camera position and target
//   light X Y Z               direction towards the first directional light
//   light-add KIND            a light of a kind of scene::light_kinds() (directional, spot, point) where
//                             the camera looks (lights.h: new_light); it becomes light number N, the last
//   light-remove N            remove light N (the panel's numbers: the view's lights from 0)
//   light-on N | light-off N  switch light N on or off (kept in the list and the view file)
//   light-move N X Y Z        move spot or point light N to (X, Y, Z) (a spot keeps its direction)
//   light-set N KEY VALUE     set a key of light N's kind (scene.h: "lights"), VALUE as JSON (null:
//                             unset); a value the scene refuses is refused with its message
//   (A light the renderer does not draw, or that it refuses with the settings, is refused with the
//   renderer's message, printed; the viewer goes on with the lights it had.)
//   split NAME | off          split screen: this technique right of the divider
//   divider F                 the divider at this fraction of the width, (0, 1)
//   load-view FILE            the camera, lights and settings of a view file (its scene must be the viewer's)
//   save-view FILE            the current view (what `msm render --view FILE` renders)
//   screenshot FILE           the window's contents, panel included, as PNG (atomic)
//   panel-mask FILE           EXR, channel "outside": 1 outside the panel, 0 on it (for msm compare --mask)
//   ground-truth N            start the ray-traced ground truth of the view, N samples per pixel (background)
//   wait-ground-truth         wait for it: its MAE, and the error image right of the divider
//   show-truth on|off         the error image right of the divider (instead of a split technique)
//   show-map on|off           the left technique's first moment image in the bottom right corner
//   resize W H                resize the window; the swapchain follows
//   frames N                  let N frames pass
//   object-frame N            the scene's animated objects at frame N (scene::at_frame), 0..100000
//   close                     close the window as its close button does
//   quit                      end the viewer (exit 0)
// Errors: ScriptError "FILE:LINE: problem"; parsing checks names, keys and values before the
// window opens.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace msm::viewer {

class ScriptError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Action {
  std::string verb;              // technique, set, camera, ...
  std::vector<std::string> args; // as written (set: key, then the rest of the line)
  int line = 0;
  std::string where; // "FILE:LINE", for messages
};

// A `set` value: JSON, or else the text itself as a string (a bare word).
nlohmann::json setting_value(const std::string& text);

std::vector<Action> parse_script(std::string_view text, const std::string& name);
std::vector<Action> load_script(const std::filesystem::path& file);

} // namespace msm::viewer
