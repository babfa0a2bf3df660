// "surface_points" (and its "points" view): the point representation re-evaluated from the
// deformed vertices, when settings or an effect asked for points (render/surface_points_pass.h).
#include "render/passes/builtin_passes.h"

namespace gi {
namespace {

class SurfacePointsEffect final : public Effect {
 public:
  explicit SurfacePointsEffect(EngineState& s) : s_(s) {}
  EffectInfo info() const override {
    EffectInfo i{"surface_points", "1",
                 "area-uniform surface points re-evaluated from the deformed vertices"};
    i.reads = {resources::kDepth};
    i.writes = {resources::kSurfacePoints, resources::kPointsView};
    return i;
  }
  std::vector<SettingDesc> settings() const override { return {}; }
  void prepare(EffectContext&, const SettingValues&) override {}
  void addPasses(FrameGraph& graph, EffectContext& ctx, const SettingValues&) override {
    if (!s_.surfacePoints) return;
    SceneGpu& sc = s_.scene;
    s_.surfacePoints->addPasses(graph, sc.currentVertices(),
                                {sc.vertices(), sc.indices(), sc.instances(), ctx.frameUniforms(),
                                 s_.nearest, sc.poseVersion()});
  }

 private:
  EngineState& s_;
};

}  // namespace

std::unique_ptr<Effect> makeSurfacePointsPass(EngineState& state) {
  return std::make_unique<SurfacePointsEffect>(state);
}

}  // namespace gi
