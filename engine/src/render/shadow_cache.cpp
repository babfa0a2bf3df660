#include "render/shadow_cache.h"

#include <algorithm>
#include <cmath>

namespace gi::shadow_cache {

std::optional<VkRect2D> coveredTexels(const glm::mat4& worldToClip, const VkRect2D& view,
                                      std::span<const Box> boxes) {
  const glm::vec2 origin(float(view.offset.x), float(view.offset.y));
  const glm::vec2 size(float(view.extent.width), float(view.extent.height));
  glm::vec2 lo(size), hi(0.0f);  // texels relative to the view's rectangle
  bool any = false;
  for (const auto& [bmin, bmax] : boxes) {
    if (!(bmin.x <= bmax.x && bmin.y <= bmax.y && bmin.z <= bmax.z)) continue;
    int out[6] = {0, 0, 0, 0, 0, 0};
    bool behindEye = false;
    glm::vec2 ndcLo(1e30f), ndcHi(-1e30f);
    for (int i = 0; i < 8; ++i) {
      const glm::vec4 c = worldToClip * glm::vec4(i & 1 ? bmax.x : bmin.x, i & 2 ? bmax.y : bmin.y,
                                                  i & 4 ? bmax.z : bmin.z, 1.0f);
      out[0] += c.x < -c.w;
      out[1] += c.x > c.w;
      out[2] += c.y < -c.w;
      out[3] += c.y > c.w;
      out[4] += c.z < 0.0f;  // reverse-Z: beyond the far plane
      out[5] += c.z > c.w;   // in front of the near plane
      if (!(c.w > 1e-6f) || !std::isfinite(c.x) || !std::isfinite(c.y)) {
        behindEye = true;
        continue;
      }
      const glm::vec2 ndc = glm::vec2(c) / c.w;
      ndcLo = glm::min(ndcLo, ndc);
      ndcHi = glm::max(ndcHi, ndc);
    }
    if (std::any_of(std::begin(out), std::end(out), [](int k) { return k == 8; })) continue;
    any = true;
    if (behindEye) {
      lo = glm::vec2(0.0f);
      hi = size;
      break;
    }
    // Viewport transform: texel = (ndc + 1) / 2 x size.
    lo = glm::min(lo, (ndcLo + 1.0f) * 0.5f * size);
    hi = glm::max(hi, (ndcHi + 1.0f) * 0.5f * size);
  }
  if (!any) return std::nullopt;
  lo = glm::clamp(glm::floor(lo) - 1.0f, glm::vec2(0.0f), size);
  hi = glm::clamp(glm::ceil(hi) + 1.0f, glm::vec2(0.0f), size);
  if (!(lo.x < hi.x && lo.y < hi.y)) return std::nullopt;
  return VkRect2D{{int32_t(origin.x + lo.x), int32_t(origin.y + lo.y)},
                  {uint32_t(hi.x - lo.x), uint32_t(hi.y - lo.y)}};
}

std::optional<VkRect2D> unite(const std::optional<VkRect2D>& a, const std::optional<VkRect2D>& b) {
  if (!a) return b;
  if (!b) return a;
  const int32_t x0 = std::min(a->offset.x, b->offset.x), y0 = std::min(a->offset.y, b->offset.y);
  const int32_t x1 =
      std::max(a->offset.x + int32_t(a->extent.width), b->offset.x + int32_t(b->extent.width));
  const int32_t y1 =
      std::max(a->offset.y + int32_t(a->extent.height), b->offset.y + int32_t(b->extent.height));
  return VkRect2D{{x0, y0}, {uint32_t(x1 - x0), uint32_t(y1 - y0)}};
}

bool sameViews(const ShadowMap& a, const ShadowMap& b) {
  if (a.width != b.width || a.height != b.height || a.views.size() != b.views.size()) return false;
  for (size_t i = 0; i < a.views.size(); ++i) {
    const ShadowMap::View &x = a.views[i], &y = b.views[i];
    if (x.viewProj != y.viewProj || x.rect.offset.x != y.rect.offset.x ||
        x.rect.offset.y != y.rect.offset.y || x.rect.extent.width != y.rect.extent.width ||
        x.rect.extent.height != y.rect.extent.height)
      return false;
  }
  return true;
}

}  // namespace gi::shadow_cache
