// The engine's point representation on the GPU (gi/surface_points.h): the "surface_points"
// compute pass that re-evaluates every point from the current vertices when the pose changed,
// published as the well-known buffer resources::kSurfacePoints, and its debug view "points". Both
// passes are culled unless something reads them (an ISM-style effect, or the view).
#pragma once

#include <cstdint>
#include <vector>

#include "gi/graph/frame_graph.h"
#include "gi/surface_points.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"

namespace gi {

class SurfacePointsPass {
 public:
  // Where each mesh instance lives in the renderer's buffers.
  struct InstanceRef {
    int node = 0, mesh = 0;
    uint32_t instance = 0;    // index into the instance buffer
    uint32_t firstIndex = 0;  // the mesh's first index in the index buffer
  };
  struct Buffers {
    VkBuffer vertices, indices, instances, frameUniforms;
    VkSampler nearest;
    // The scene's pose version (SceneGpu::poseVersion), read when the pass records: the
    // points are re-evaluated only when it changed since the last evaluation.
    const uint64_t* poseVersion = nullptr;
  };

  // Samples `count` points over `scene` at its current pose and uploads them.
  SurfacePointsPass(vk::Context& ctx, const Scene& scene, uint32_t count, uint64_t seed,
                    const std::vector<InstanceRef>& instances);

  // Adds "surface_points" (and the "points" view pass) to the graph; `vertices` is the
  // deformed vertex buffer's current version when the skinning pass exists (else invalid).
  void addPasses(FrameGraph& graph, BufferHandle vertices, const Buffers& buffers);

  const SurfacePointSet& set() const { return set_; }
  uint32_t count() const { return uint32_t(set_.points.size()); }
  // The points as the last executed frame left them (waits for the device); empty until a
  // frame ran the "surface_points" pass (it is culled when nothing reads the points).
  std::vector<SurfacePointSample> read(vk::Context& ctx) const;
  bool evaluated() const { return evaluated_; }
  // How many frames re-evaluated the points (a static pose is evaluated once).
  uint64_t evaluations() const { return evaluations_; }

 private:
  struct UpdatePush {  // surface_points.comp's push constants
    uint32_t count;
    float areaPerPoint;
  };
  struct ViewPush {  // points_view.comp's
    uint32_t count, clear;
  };
  SurfacePointSet set_;
  vk::Buffer samples_, points_;
  vk::Pipeline update_, view_;
  bool evaluated_ = false;
  uint64_t evaluations_ = 0, evaluatedVersion_ = 0;
};

}  // namespace gi
