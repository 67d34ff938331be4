// Internal helpers of msm_scene (not installed).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

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

// What import_model checks in its own process before Assimp runs: a regular file, its header
// (check_mesh_header).
void check_mesh_file(const std::filesystem::path& file);

// import_model runs Assimp in a child process (import_child.cpp; docs/architecture.md "Mesh import
// in a child process"); these are its parts.
// Assimp and the conversion to parts in this process (import.cpp), after check_mesh_file.
std::vector<ModelPart> import_model_in_process(const std::filesystem::path& file);
// The parts as the child sends them to the parent (embedded images once each, shared as before).
std::string serialize_model(const std::vector<ModelPart>& parts);
// A SceneError as the child sends it.
std::string serialize_error(const SceneError& error);
// The child's bytes back to parts, or its SceneError rethrown; every count and size is checked
// against the bytes there are and every index against what it indexes (SceneError naming `file`
// for anything inconsistent or truncated: the child's bytes are not trusted either).
std::vector<ModelPart> deserialize_model(std::string_view bytes, const std::filesystem::path& file);
// Seconds the child may take: MSM_IMPORT_TIMEOUT_S, default kImportTimeoutSeconds.
double import_timeout_seconds();
// Test hook (tests only, null otherwise): called in the child before Assimp, to make it crash,
// hang or allocate without end.
extern void (*import_child_hook)();

// A light of a glTF 2.0 file (KHR_lights_punctual) in the file's frame: its node's world position
// and -Z axis (not normalized: the node's scale is in it), its colour times intensity, its cone
// half-angles in degrees (glTF's radians converted) and range where given.
struct FileLight {
  std::size_t index = 0; // in the file's "lights"
  std::string name;
  LightKind kind = LightKind::point;
  glm::vec3 position{0.0f}, direction{0.0f, 0.0f, -1.0f}, intensity{1.0f};
  float inner_cone_deg = 0.0f, outer_cone_deg = 45.0f;
  std::optional<float> range;
};
// The lights of the nodes of a .gltf or .glb file's scene (its "scene", else its first; without
// scenes every root node), read from its JSON; none without KHR_lights_punctual. SceneError("", "",
// problem) for another format, malformed JSON or a hierarchy that is not a tree.
std::vector<FileLight> gltf_lights(const std::filesystem::path& file);

} // namespace msm::scene::detail
