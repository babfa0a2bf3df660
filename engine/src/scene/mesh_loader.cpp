// loadMeshFile: a bare .obj/.ply model becomes a scene with one root node per mesh, a default
// camera framing it and a sun (the format readers live in obj_loader.cpp / ply_loader.cpp).
#include <filesystem>

#include "gi/errors.h"
#include "gi/scene_io.h"
#include "scene_io_util.h"

namespace gi {

Scene detail::loadMeshFileOnly(const std::string& path) {
  const std::string ext = detail::lowerExtension(path);
  detail::MeshFileData data;
  bool weld = false;
  if (ext == ".obj") {
    data = detail::readObj(path);
    weld = true;  // flat-shaded faces are emitted unshared; merge identical corners again
  } else if (ext == ".ply") {
    data = detail::readPly(path);
  } else {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      throw Error(ErrorKind::FileNotFound, path, "file does not exist");
    throw Error(ErrorKind::Unsupported, path,
                "unsupported mesh format '" + ext + "' (expected .obj or .ply)");
  }

  Scene scene;
  scene.sourcePath = path;
  scene.materials = std::move(data.materials);
  scene.textures = std::move(data.textures);
  scene.warnings = std::move(data.warnings);
  if (scene.materials.empty()) scene.materials.push_back(Material{.name = "default"});
  detail::addProcessedMeshes(scene, std::move(data.meshes), path, weld);
  scene.updateWorldTransforms();
  return scene;
}

Scene loadMeshFile(const std::string& path) {
  Scene scene = detail::loadMeshFileOnly(path);
  addDefaultCameraAndLight(scene);
  return scene;
}

}  // namespace gi
