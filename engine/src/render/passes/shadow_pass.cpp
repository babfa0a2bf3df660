// One "shadow_<light>" pass per shadow-casting light, each drawing the scene depth-only
// through GpuScene into its own layer of "shadow_maps" (D32 reverse-Z 2-D array; a point light's
// six faces share its layer as a 3x2 atlas). Without shadowed lights "shadow_maps" is the
// engine's 1x1 array cleared to "no occluder". Only readers keep these passes alive.
//
// The maps persist across frames and cost only what changed (RenderSettings::cacheShadows):
// while a light's views and the static casters stay the same, its map's static depth lives in
// a cache image; a frame copies back the texels the dynamic casters covered last time or cover
// now and draws only the dynamic casters over them. A light whose views changed since the last
// frame (it moves) is drawn whole, as without the cache; its cache is built the first frame it
// stands still. Each frame's maps are the same, bit for bit, as drawing everything.
// With RenderSettings::shadowUpdatePeriod N > 1 a moving light is drawn whole (and cached) only
// every N-th frame, the lights staggered; in between its map keeps the views it was drawn with,
// the shadow view records say so (its shadows lag the light), and only the dynamic casters are
// redrawn into it, as for a still light.
#include <algorithm>
#include <optional>

#include "gi/vk/common.h"
#include "render/passes/builtin_passes.h"
#include "render/shadow_cache.h"

namespace gi {
namespace {

namespace res = resources;

// A D32 2-D array cleared to 0 (reverse-Z: no occluder), left SHADER_READ_ONLY_OPTIMAL.
vk::Image makeDepthArray(vk::Context& ctx, uint32_t width, uint32_t height, uint32_t layers,
                         VkImageUsageFlags usage) {
  vk::ImageDesc d;
  d.format = kSceneDepthFormat;
  d.width = width;
  d.height = height;
  d.layers = layers;
  d.usage = usage | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
            VK_IMAGE_USAGE_TRANSFER_SRC_BIT;  // readTarget("shadow_maps") copies from it
  d.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  vk::Image img(ctx, d);
  ctx.submitAndWait([&](VkCommandBuffer c) {
    vk::imageBarrier(c, img.handle(), VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                     VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkClearDepthStencilValue zero{0.0f, 0};
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, layers};
    vkCmdClearDepthStencilImage(c, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1,
                                &range);
    vk::imageBarrier(c, img.handle(), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
  });
  return img;
}

constexpr VkPipelineStageFlags2 kDepthStages =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
constexpr VkAccessFlags2 kDepthAccess =
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;

// One layer's layout change inside a pass (the graph syncs the pass as a whole).
void layerBarrier(VkCommandBuffer c, VkImage image, uint32_t layer, VkImageLayout from,
                  VkImageLayout to, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                  VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
  vk::imageBarrier(c, image, {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, layer, 1}, from, to, srcStage,
                   srcAccess, dstStage, dstAccess);
}

std::vector<SceneView> sceneViews(const ShadowMap& map) {
  std::vector<SceneView> views;
  for (const ShadowMap::View& v : map.views) {
    SceneView sv;
    sv.proj = v.viewProj;  // world -> clip as one matrix
    sv.viewport = v.rect;
    views.push_back(sv);
  }
  return views;
}

class ShadowPass final : public Effect {
 public:
  explicit ShadowPass(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"shadows", "1", "shadow maps of the shadow-casting lights, one array layer each"};
    i.writes = {res::kShadowMaps};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext& ctx, const SettingValues&) override {
    if (!noShadows_) noShadows_ = makeDepthArray(ctx.vulkan(), 1, 1, 1, 0);
  }
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    const LightSetup& setup = s_.lights;
    const bool none = setup.maps.empty();
    const vk::Image& image = none ? noShadows_ : mapsFor(ctx.vulkan(), setup);
    TextureDesc desc{kSceneDepthFormat, SizeClass::Absolute, 1.0f, image.desc().width,
                     image.desc().height};
    desc.type = TextureType::Tex2DArray;
    desc.layers = image.desc().layers;
    TextureHandle maps = graph.importTexture(res::kShadowMaps, image.handle(), image.view(), desc,
                                             VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                             VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    GpuScene& scene = ctx.scene();
    for (uint32_t slot = 0; !none && slot < setup.maps.size(); ++slot) {
      auto io = std::make_shared<TextureHandle>();
      graph.addPass(
          "shadow_" + std::to_string(setup.maps[slot].light),
          [&](PassBuilder& b) {
            scene.declareRead(b);
            *io = maps = b.write(maps, TextureUsage::DepthAttachment, Subresource::layerOf(slot));
          },
          [this, io, slot](PassContext& pc) { record(pc, slot, *io); });
    }
    graph.blackboard().put(res::kShadowMaps, maps);
  }

 private:
  // What a layer of the maps and its cache hold.
  struct Slot {
    std::optional<ShadowMap> drawn;  // the views the layer was last drawn with
    std::vector<glm::vec4> params;   // their shadow view records' params (near, far, texel)
    uint32_t frame = 0;              // frames recorded: with the slot's index, its update phase
    uint64_t staticVersion = 0;      // SceneGpu::staticVersion() then
    vk::Image cache;                 // static casters' depth (map.width x map.height), or none
    bool cached = false;             // `cache` holds `drawn`'s static depth
    std::vector<std::optional<VkRect2D>> dynamicTexels;  // per view, last drawn
  };

  // The persistent maps for this layout: recreated (and every cache dropped) when it changes.
  const vk::Image& mapsFor(vk::Context& ctx, const LightSetup& setup) {
    const uint32_t w = setup.layerWidth(), h = setup.layerHeight(),
                   layers = uint32_t(setup.maps.size());
    if (!maps_ || maps_.desc().width != w || maps_.desc().height != h ||
        maps_.desc().layers != layers) {
      maps_ = makeDepthArray(ctx, w, h, layers, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
      slots_.clear();
    }
    slots_.resize(layers);
    return maps_;
  }

  void record(PassContext& pc, uint32_t index, TextureHandle maps) {
    SceneGpu& scene = s_.scene;
    const ShadowMap& current = s_.lights.maps[index];
    Slot& slot = slots_[index];
    const RenderSettings& rs = s_.settings;
    const uint32_t period = rs.cacheShadows ? std::max(rs.shadowUpdatePeriod, 1u) : 1u;
    const bool staticSame = slot.drawn && slot.staticVersion == scene.staticVersion();
    const bool viewsSame = slot.drawn && shadow_cache::sameViews(*slot.drawn, current);
    // A moving light keeps the views its map was drawn with except on its frame of the period
    // (the lights' frames are staggered by their index).
    const bool keep = staticSame && !viewsSame && slot.cached && (slot.frame + index) % period != 0;
    ++slot.frame;
    SceneTargets layer;
    layer.depth = pc.view(maps, Subresource::layerOf(index));
    layer.extent = pc.extent(maps);
    if (!rs.cacheShadows || !staticSame || !(viewsSame || keep)) {
      // Drawn whole: the light moved (on its frame), the static casters changed, or no cache.
      slot.drawn = current;
      slot.params.clear();
      for (size_t v = 0; v < current.views.size(); ++v)
        slot.params.push_back(s_.lights.views[current.firstView + v].params);
      slot.staticVersion = scene.staticVersion();
      slot.cached = false;
      slot.dynamicTexels.assign(current.views.size(), std::nullopt);
      if (period == 1) {
        scene.drawDepth(pc, layer, sceneViews(current));
        ++s_.shadowMapsDrawn;
        return;
      }
      // Amortised: the cache is built now, so that the frames keeping these views restore only
      // what the dynamic casters cover.
    } else if (keep) {
      keepDrawnViews(index, slot);
    }
    drawFromCache(pc, index, slot, layer);
  }

  // The lighting pass and the effects read a kept map with the views it was drawn with: its
  // shadow view records (GPU and CPU copies) become those views seen from today's camera.
  void keepDrawnViews(uint32_t index, const Slot& slot) {
    const ShadowMap& current = s_.lights.maps[index];
    for (size_t v = 0; v < current.views.size(); ++v) {
      GpuShadowView& record = s_.lights.views[current.firstView + v];
      record.viewToClip = slot.drawn->views[v].viewProj * s_.lights.cameraInvView;
      record.params = slot.params[v];
      s_.lightBuffers->writeShadowView(uint32_t(current.firstView + v), record);
    }
  }

  // The slot's drawn views from its cache: restores what the dynamic casters covered and cover
  // (or the whole map when the cache is built now), then draws the dynamic casters.
  void drawFromCache(PassContext& pc, uint32_t index, Slot& slot, SceneTargets layer) {
    SceneGpu& scene = s_.scene;
    const ShadowMap& map = *slot.drawn;
    const std::vector<SceneView> views = sceneViews(map);
    VkCommandBuffer c = pc.cmd();
    // Texels to restore from the cache: the whole map when the cache is built now, else the
    // dynamic casters' last and current texels.
    std::vector<VkImageCopy> copies;
    const std::vector<shadow_cache::Box>& dynamic = scene.dynamicBoxes();
    std::vector<SceneView> dynamicViews;
    for (size_t v = 0; v < views.size(); ++v) {
      const std::optional<VkRect2D> now =
          shadow_cache::coveredTexels(map.views[v].viewProj, map.views[v].rect, dynamic);
      const std::optional<VkRect2D> restore = shadow_cache::unite(now, slot.dynamicTexels[v]);
      slot.dynamicTexels[v] = now;
      if (now) dynamicViews.push_back(views[v]);
      if (!restore || !slot.cached) continue;
      VkImageCopy copy{};
      copy.srcSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
      copy.dstSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, index, 1};
      copy.srcOffset = copy.dstOffset = {restore->offset.x, restore->offset.y, 0};
      copy.extent = {restore->extent.width, restore->extent.height, 1};
      copies.push_back(copy);
    }
    if (!slot.cached) {
      buildCache(pc, slot, map, views);
      VkImageCopy copy{};
      copy.srcSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
      copy.dstSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, index, 1};
      copy.extent = {map.width, map.height, 1};
      copies = {copy};
      ++s_.shadowMapsDrawn;
    } else {
      ++s_.shadowMapsCached;
    }
    if (!copies.empty()) {
      layerBarrier(c, maps_.handle(), index, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, kDepthStages, kDepthAccess,
                   VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
      vkCmdCopyImage(c, slot.cache.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, maps_.handle(),
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(copies.size()), copies.data());
      layerBarrier(c, maps_.handle(), index, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                   VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                   VK_ACCESS_2_TRANSFER_WRITE_BIT, kDepthStages, kDepthAccess);
    }
    if (!dynamicViews.empty()) {
      layer.clear = false;
      scene.drawDepth(pc, layer, dynamicViews, SceneGpu::Subset::Dynamic);
    }
  }

  // Draws the static casters into the slot's cache (made on first use), left TRANSFER_SRC.
  void buildCache(PassContext& pc, Slot& slot, const ShadowMap& map,
                  const std::vector<SceneView>& views) {
    VkCommandBuffer c = pc.cmd();
    VkImageLayout from = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    if (!slot.cache || slot.cache.desc().width != map.width ||
        slot.cache.desc().height != map.height) {
      vk::ImageDesc d;
      d.format = kSceneDepthFormat;
      d.width = map.width;
      d.height = map.height;
      d.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
      slot.cache = vk::Image(pc.context(), d);
      from = VK_IMAGE_LAYOUT_UNDEFINED;
    }
    vk::imageBarrier(c, slot.cache.handle(), VK_IMAGE_ASPECT_DEPTH_BIT, from,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                     kDepthStages, kDepthAccess);
    SceneTargets t;
    t.depth = slot.cache.view();
    t.extent = {map.width, map.height};
    s_.scene.drawDepth(pc, t, views, SceneGpu::Subset::Static);
    vk::imageBarrier(c, slot.cache.handle(), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     kDepthStages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    slot.cached = true;
  }

  EngineState& s_;
  vk::Image noShadows_;  // 1x1 one-layer D32 array cleared to 0: "shadow_maps" without shadows
  vk::Image maps_;       // "shadow_maps" when lights cast shadows: one layer per map
  std::vector<Slot> slots_;
};

}  // namespace

std::unique_ptr<Effect> makeShadowPass(EngineState& state) {
  return std::make_unique<ShadowPass>(state);
}

}  // namespace gi
