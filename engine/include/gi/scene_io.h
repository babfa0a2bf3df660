// Loading scenes from files. Every function throws gi::Error naming the file and the problem;
// on success the Scene has world transforms updated, normals valid (recomputed where missing
// or degenerate), per-triangle areas and bounds filled, and at least one material.
#pragma once

#include <string>

#include "gi/scene.h"

namespace gi {

// Dispatches on the extension: .json scene description, .gltf/.glb, .obj, .ply;
// "default" gives the built-in scene.
Scene loadScene(const std::string& pathOrDefault);

Scene loadGltf(const std::string& path);       // glTF 2.0 (.gltf / .glb) via tinygltf
Scene loadMeshFile(const std::string& path);   // .obj / .ply via OpenMesh
Scene loadSceneJson(const std::string& path);  // assets/scenes/*.json
Scene makeDefaultScene();                      // Cornell-box-like room, built in code

// Adds a default camera/light/sky when a scene has none (used for bare model files).
void addDefaultCameraAndLight(Scene& scene);

// Mesh processing (OpenMesh): recompute missing/degenerate normals, drop non-finite and
// degenerate triangles, weld duplicate vertices when asked, fill triangleAreas and bounds.
// Returns a human-readable list of what was changed (empty if nothing).
struct MeshFixReport {
  size_t recomputedNormals = 0;
  size_t droppedNonFiniteTriangles = 0;
  size_t droppedDegenerateTriangles = 0;
  size_t weldedVertices = 0;
};
MeshFixReport processMesh(Mesh& mesh, bool weld = false);

}  // namespace gi
