// The frame: the engine's G-buffer, lighting, tonemap and floor passes plus the effects the
// scene asks for, assembled into a frame graph that keeps only what reaches the requested
// view. Renders headless into offscreen targets that can be read back.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gi/effect_registry.h"
#include "gi/image_io.h"
#include "gi/render_settings.h"
#include "gi/scene.h"
#include "gi/settings.h"
#include "gi/surface_points.h"
#include "gi/vk/context.h"

namespace gi {

struct PassTiming {
  std::string name;
  double ms = 0.0;
  // With RenderSettings::isolatePasses: the process's CPU time over the pass (recording,
  // submission, execution on every driver thread, the wait), ms. On a CPU driver (lavapipe) this
  // is the pass's work, which other processes sharing the cores do not inflate as they inflate
  // the wall-clock timestamps of `ms`. Negative without isolatePasses.
  double cpuMs = -1.0;
};

class Renderer {
 public:
  // `scene` must outlive the renderer (it is read, not copied: pass a named Scene, never a
  // temporary); so must `registry` when effects are requested.
  Renderer(vk::Context& ctx, const Scene& scene, const RenderSettings& settings,
           const EffectRegistry* registry = nullptr);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Records, submits and waits for one frame; per-pass GPU times end up in lastTimings().
  void renderFrame();
  // Poses the scene's animations at `seconds` (all clips, looping) for the next frames: node
  // transforms, joint matrices and morph weights. Skinned and morphed meshes are deformed on
  // the GPU by the "skinning" pass, only where their joints or weights changed. The previous
  // model matrices feed the motion vectors.
  void setTime(double seconds);
  // Vertices the skinning pass deformed in the last frame (0 when nothing changed).
  uint32_t lastSkinnedVertexCount() const;
  // The GPU-deformed vertices of every skinned/morphed mesh instance (read back; for tests).
  struct DeformedMesh {
    int node = 0, mesh = 0;  // scene indices
    std::vector<Vertex> vertices;
  };
  std::vector<DeformedMesh> readDeformedMeshes();
  // The point representation: the samples (empty set when there are none) and the world
  // positions/normals the "surface_points" pass wrote in the last frame that ran it.
  const SurfacePointSet& surfacePoints() const;
  std::vector<SurfacePointSample> readSurfacePoints();
  // Frames whose "surface_points" pass re-evaluated the points: only those after the pose
  // changed (animated instances, skinning or morph weights); a static scene's points once.
  uint64_t surfacePointEvaluations() const;
  const std::vector<PassTiming>& lastTimings() const;
  std::vector<std::string> passNames() const;        // passes the graph executes, in order
  std::vector<std::string> culledPassNames() const;  // passes declared but culled
  // Said on the last graph build, one line each: an enabled effect every pass of which was
  // culled (nothing it writes reaches the view or a kept output). Apps print them.
  const std::vector<std::string>& warnings() const;
  // Each enabled effect, in the order its passes were added, with how many of its passes the
  // graph runs: 0 means nothing it writes reaches the view (a warning says so).
  struct EffectPasses {
    std::string effect;
    size_t run = 0, total = 0;
  };
  std::vector<EffectPasses> effectPasses() const;
  // True for passes the engine's built-in stages added (G-buffer, skinning, surface points,
  // shadows, lighting, tonemap, floor), false for effects' passes.
  bool isEnginePass(const std::string& pass) const;
  std::string graphDescription() const;  // gi-render --print-graph
  std::string graphDot() const;          // Graphviz
  double lastCompileMs() const;          // CPU time of the last graph build + compile
  // Instance draws the last frame recorded and skipped by frustum culling (all views), and
  // its shadow maps drawn whole (including a cache being built) and restored from their cache
  // (only the dynamic casters drawn; RenderSettings::cacheShadows).
  struct DrawCounts {
    uint64_t drawn = 0, culled = 0;
    uint32_t shadowMapsDrawn = 0, shadowMapsCached = 0;
  };
  DrawCounts lastFrameDraws() const;

  // Changes one effect's settings: uniform-only changes apply next frame; a change of a
  // setting marked `changesGraph` re-prepares the effect and recompiles the graph.
  void setEffectSettings(const std::string& effect, const SettingValues& values);
  bool graphRecompiledByLastChange() const;
  // Live changes (no reconstruction; the graph is recompiled). Effects that stay keep their
  // instance; a configuration that fails (unknown effect or view) throws and leaves the
  // renderer as it was.
  void setEffects(const std::vector<EffectConfig>& effects);
  void setView(const std::string& view);
  // Everything in RenderSettings at once: size (resize), engine settings, view, effects.
  void applySettings(const RenderSettings& settings);
  const RenderSettings& settings() const;

  ImageRGBA8 readOutput();                           // tonemapped 8-bit image (view "output")
  ImageRGBA32F readTarget(const std::string& name);  // any produced resource as float RGBA
  // Its texels as stored, tightly packed rows (e.g. the packed "gbuffer", gi/gbuffer.h).
  std::vector<uint8_t> readTargetBytes(const std::string& name);
  std::vector<std::string> viewNames() const;  // images that can be viewed / read
  // Every texture the last frame's graph used (G-buffer, effects' transients, history,
  // fallbacks, imports), mip 0 / layer 0. `image` holds float RGBA for formats readTarget
  // reads; other formats (packed integer texels) come back with `decoded` false and no pixels.
  // With aliasTransients (the default) a transient may hold a later alias's texels.
  struct NamedTexture {
    std::string name;
    VkFormat format = VK_FORMAT_UNDEFINED;
    bool decoded = false;
    ImageRGBA32F image;
  };
  std::vector<NamedTexture> readAllTextures();
  const CameraView& camera() const;
  // A free camera (gi-demo's) in place of the scene's: `view` (rigid), `position`, `yfov`,
  // `znear`, `zfar` are kept; `proj` is rebuilt for the output's aspect (also on resize).
  // nullopt returns to the scene's camera. Lights and shadow views are re-planned for it.
  void setCameraOverride(const std::optional<CameraView>& camera);
  // The tonemapped RGBA8 image; after renderFrame() it is in VK_IMAGE_LAYOUT_GENERAL and all
  // writes are complete (a presenter copies it into a swapchain image).
  VkImage outputImage() const;
  VkExtent2D outputExtent() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
