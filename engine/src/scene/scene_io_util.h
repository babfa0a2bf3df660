// Helpers shared by the OBJ/PLY/JSON loaders and the built-in scene (internal to gi_scene).
#pragma once

#include <string>
#include <vector>

#include "gi/scene.h"

namespace gi::detail {

// Whole file as text. Throws FileNotFound (missing, a directory, unreadable) or EmptyFile
// (zero bytes or only whitespace).
std::string readTextFile(const std::string& path);
// Lower-case extension including the dot (".obj"), empty when there is none.
std::string lowerExtension(const std::string& path);

// Format readers behind loadMeshFile: meshes (not yet processed) plus their materials.
struct MeshFileData {
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<std::string> warnings;
};
MeshFileData readObj(const std::string& path);
MeshFileData readPly(const std::string& path);

// Runs processMesh over every mesh (reporting repairs as scene warnings), removes meshes left
// without triangles, and places one root node per mesh. Throws NonFinite/InvalidData (naming
// `path`) when no triangle survives. Does not add cameras or lights.
void addProcessedMeshes(Scene& scene, std::vector<Mesh> meshes, const std::string& path, bool weld);

// loadMeshFile without the default camera and light (for models placed by a JSON scene).
Scene loadMeshFileOnly(const std::string& path);

// Appends `model` to `scene` under a new root node (`name`, `transform`), offsetting its mesh,
// material, texture, camera, light, skin and node indices (skin joints, node skins, animation
// channel targets). The model's environment and effects are dropped; its warnings, cameras,
// lights, skins, animation clips and morph weights are kept. World transforms are not updated.
// Returns the new root node's index.
int mergeScene(Scene& scene, Scene model, const std::string& name, const glm::mat4& transform);

// Built-in primitives (object space, y up, outward normals, uv in [0,1]), already processed.
Mesh makePlane(float sizeX, float sizeZ);               // in y = 0, facing +y, centred
Mesh makeBox(const glm::vec3& size, int segments = 1);  // centred at the origin; s x s quads a face
Mesh makeSphere(float radius, int segments, int rings);  // UV sphere centred at the origin

}  // namespace gi::detail
