// Internal helpers of msm_scene (not installed).
#pragma once

#include <string>

#include "msm/scene/scene.h"

namespace msm::scene::detail {

// Rejects NaN/infinite positions (SceneError("", where, ...)), normalizes normals, drops
// degenerate triangles; throws when no triangle is left.
void finalize_mesh(Mesh& mesh, const std::string& where);

// Flips triangles [first_triangle, end) whose winding disagrees with their vertex normals.
void fix_winding(Mesh& mesh, std::size_t first_triangle);

} // namespace msm::scene::detail
