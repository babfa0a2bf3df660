// Shadow maps that cost only what changed: each light's map keeps a cached copy of its static
// casters' depth; a frame copies back the texels the dynamic casters covered then or cover now
// and draws the dynamic casters over them. These are the pure parts (no device), tested alone.
#pragma once

#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "render/light_setup.h"

namespace gi::shadow_cache {

using Box = std::pair<glm::vec3, glm::vec3>;  // world-space min, max

// The texels of a view (its rectangle in the map) that the boxes may cover: their projected
// corners' bounds widened by one texel for rasterisation's rounding, clipped to the rectangle.
// A box reaching behind a perspective view's eye plane covers the whole rectangle (its
// projection is unbounded); boxes outside the clip volume cover nothing. nullopt: nothing.
std::optional<VkRect2D> coveredTexels(const glm::mat4& worldToClip, const VkRect2D& view,
                                      std::span<const Box> boxes);

// The smallest rectangle holding both (either may be absent).
std::optional<VkRect2D> unite(const std::optional<VkRect2D>& a, const std::optional<VkRect2D>& b);

// What a map's static depth depends on besides the static casters: its views, bit for bit.
bool sameViews(const ShadowMap& a, const ShadowMap& b);

}  // namespace gi::shadow_cache
