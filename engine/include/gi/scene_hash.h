// A fingerprint of everything a loaded scene renders from: geometry, materials, textures,
// lights, cameras, node transforms, skins, animations and the environment (its map's texels
// included). Caches of results computed from a scene (gi-bench's CPU references) key on it, so
// an edit to any file the scene reads (a mesh, a texture, an environment map) is a new key,
// while the path it was loaded from is not part of it.
#pragma once

#include <cstdint>

#include "gi/scene.h"

namespace gi {

uint64_t sceneContentHash(const Scene& scene);

}  // namespace gi
