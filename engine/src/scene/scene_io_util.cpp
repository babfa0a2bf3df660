#include "scene_io_util.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "gi/errors.h"
#include "gi/input_file.h"
#include "gi/scene_io.h"

namespace gi::detail {

namespace fs = std::filesystem;

std::string readTextFile(const std::string& path) {
  std::string s = readInputFile(path);  // regular files only, size-limited
  if (std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isspace(c); }))
    throw Error(ErrorKind::EmptyFile, path, "file is empty");
  return s;
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void addProcessedMeshes(Scene& scene, std::vector<Mesh> meshes, const std::string& path,
                        bool weld) {
  size_t kept = 0, nonFinite = 0;
  for (Mesh& mesh : meshes) {
    // Readers mark absent normals as (0,0,0): computing those is routine, not worth a warning.
    const size_t absentNormals = static_cast<size_t>(
        std::count_if(mesh.vertices.begin(), mesh.vertices.end(),
                      [](const Vertex& v) { return v.normal == glm::vec3(0.0f); }));
    MeshFixReport r = processMesh(mesh, weld);
    nonFinite += r.droppedNonFiniteTriangles;
    const std::string who = path + ": mesh '" + mesh.name + "': ";
    if (r.droppedNonFiniteTriangles)
      scene.warnings.push_back(who + "dropped " + std::to_string(r.droppedNonFiniteTriangles) +
                               " triangles with NaN/Inf positions");
    if (r.droppedDegenerateTriangles)
      scene.warnings.push_back(who + "dropped " + std::to_string(r.droppedDegenerateTriangles) +
                               " degenerate triangles");
    if (r.recomputedNormals > absentNormals)
      scene.warnings.push_back(who + "recomputed " +
                               std::to_string(r.recomputedNormals - absentNormals) +
                               " invalid (NaN/Inf) vertex normals");
    if (mesh.triangleCount() == 0) {
      scene.warnings.push_back(who + "no usable triangles left, mesh skipped");
      continue;
    }
    scene.meshes.push_back(std::move(mesh));
    int node = scene.addNode(scene.meshes.back().name, glm::mat4(1.0f));
    scene.nodes[node].meshes.push_back(static_cast<int>(scene.meshes.size()) - 1);
    ++kept;
  }
  if (kept == 0 && nonFinite > 0)
    throw Error(ErrorKind::NonFinite, path,
                "every triangle has NaN/Inf positions; no geometry left");
  if (kept == 0) throw Error(ErrorKind::InvalidData, path, "no triangles (no usable geometry)");
}

int mergeScene(Scene& scene, Scene model, const std::string& name, const glm::mat4& transform) {
  const int meshOffset = static_cast<int>(scene.meshes.size());
  const int materialOffset = static_cast<int>(scene.materials.size());
  const int textureOffset = static_cast<int>(scene.textures.size());
  const int cameraOffset = static_cast<int>(scene.cameras.size());
  const int lightOffset = static_cast<int>(scene.lights.size());
  const int skinOffset = static_cast<int>(scene.skins.size());
  const int parent = scene.addNode(name, transform);
  const int nodeOffset = static_cast<int>(scene.nodes.size());

  for (Texture& t : model.textures) scene.textures.push_back(std::move(t));
  for (Material& m : model.materials) {
    if (m.baseColorTexture >= 0) m.baseColorTexture += textureOffset;
    scene.materials.push_back(std::move(m));
  }
  for (Mesh& m : model.meshes) {
    m.material += static_cast<uint32_t>(materialOffset);
    scene.meshes.push_back(std::move(m));
  }
  for (Camera& c : model.cameras) scene.cameras.push_back(std::move(c));
  for (Light& l : model.lights) scene.lights.push_back(std::move(l));
  for (Node& n : model.nodes) {
    n.parent = n.parent < 0 ? parent : n.parent + nodeOffset;
    for (int& c : n.children) c += nodeOffset;
    for (int& m : n.meshes) m += meshOffset;
    if (n.camera >= 0) n.camera += cameraOffset;
    if (n.light >= 0) n.light += lightOffset;
    if (n.skin >= 0) n.skin += skinOffset;
    scene.nodes.push_back(std::move(n));  // morph weights travel with the node
  }
  // Skins and clips refer to nodes by index; -1 (a joint outside the displayed scene) stays.
  for (Skin& skin : model.skins) {
    for (int& j : skin.joints)
      if (j >= 0) j += nodeOffset;
    scene.skins.push_back(std::move(skin));
  }
  for (AnimationClip& clip : model.animations) {
    for (AnimationChannel& ch : clip.channels)
      if (ch.node >= 0) ch.node += nodeOffset;
    scene.animations.push_back(std::move(clip));
  }
  for (int r : model.roots) scene.nodes[parent].children.push_back(r + nodeOffset);
  if (scene.activeCameraNode < 0 && model.activeCameraNode >= 0)
    scene.activeCameraNode = model.activeCameraNode + nodeOffset;
  for (std::string& w : model.warnings) scene.warnings.push_back(std::move(w));
  return parent;
}

}  // namespace gi::detail
