// Measuring configurations: each rendered for a few frames per repetition, repetitions
// interleaved across a batch of renderers (stats.h's timing model), then scored against its
// reference over the pixels that are geometry in both.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "comparison.h"
#include "gi/renderer.h"
#include "metrics.h"
#include "setup.h"

namespace gi_bench {

// The rendered configuration: its timings over the repetitions and, after the last one, the
// compared resource and the depth (dropped once scored).
struct Measurement {
  std::vector<gi::bench::PassTime> passes;
  Interval total, effect, floor, wall;
  std::vector<double> effectReps, floorReps;  // per repetition, in order
  std::vector<double> effectRepsMin;          // per repetition: fastest frames
  std::vector<double> effectRepsCpu;          // per repetition: CPU ms (--isolate-passes)
  size_t batch = 0;  // interleave batch: only configurations of one batch share rounds
  gi::ImageRGBA32F out, depth;
  gi::ImageRGBA32F emission;  // --exclude-emitters only
};

// What a configuration renders.
struct RenderJob {
  const gi::Scene* scene = nullptr;
  const gi::RenderSettings* settings = nullptr;  // effects and engine settings
  std::string resource;                          // read back after the last repetition
};

// The effect's output against one reference, over pixels that are geometry in both.
struct Scores {
  gi::bench::Metrics metrics;
  Row::AoSplit split;
};

// Renders every job (at most a batch of renderers alive at once; repetitions interleaved);
// `scoreNow(i, m)` is called once job i is measured, while its images are held.
std::vector<Measurement> measureAll(
    gi::vk::Context& ctx, const gi::EffectRegistry& registry, const std::vector<RenderJob>& jobs,
    const Options& o, bool floorPass,
    const std::function<void(size_t, const Measurement&)>& scoreNow);
// Throws gi::Error naming `scene` when no pixel is geometry in both the frame and the
// reference (an empty scene, a camera that sees nothing): nothing would be scored.
Scores score(const Measurement& m, const ReferenceSpec& spec, const Reference& reference,
             const Options& o, const std::string& scene);
// Scores against `reference` within each of the scene's regions (the reference's primary hit
// inside the region's box), as score() over the whole image.
std::vector<Row::RegionScore> regionScores(const Measurement& m, const ReferenceSpec& spec,
                                           const Reference& reference, const Options& o,
                                           const gi::Scene& scene);
// The part of the error against the target that the declared quantity's own distance from it
// explains (metrics.h QuantityGap); nullopt when the effect declares its target.
std::optional<gi::bench::QuantityGap> gapOf(const Measurement& m, const Comparison& cmp,
                                            const Reference& target, const Reference& declared,
                                            const Options& o);

}  // namespace gi_bench
