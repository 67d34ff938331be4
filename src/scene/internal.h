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

// Before Assimp: what the mesh file's header declares (PLY, OFF, OBJ, glTF, GLB). SceneError for
// a file that declares more triangles than limits::max_triangles() (refused before Assimp
// allocates for them) and for PLY and OFF headers that cannot be right (no end_header; more
// elements than the file's size can hold: truncated).
void check_mesh_header(const std::filesystem::path& file);

} // namespace msm::scene::detail
