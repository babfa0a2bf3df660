// What a configuration's frame is compared with: the resource read and the reference
// quantities for the declared estimate and the physical target.
#pragma once

#include <string>
#include <vector>

#include "gi/effect_registry.h"
#include "gi/render_settings.h"
#include "options.h"
#include "quantity.h"

namespace gi_bench {

struct Comparison {
  std::string resource = gi::resources::kLit;  // what the frame is read at
  ReferenceSpec declared, target;              // what it estimates; its physical target
  std::string effect;                          // the effect that decided it ("" for the engine)
};

// The first effect with an AO-like declaration or target decides (its "ao" is compared), else
// the first that estimates indirect light, else direct light. `aoSplit`: the AO target is the
// ao-split reference (its value is AO_full).
Comparison comparisonFor(const std::vector<gi::EffectConfig>& effects,
                         const gi::EffectRegistry& registry, bool aoSplit);
// --target: the lit image against one light quantity, whatever the effects estimate.
Comparison litAgainst(Comparison c, ref::Quantity target);
// Direct+indirect references also name their bounces (--ref-bounces) and "dark-emitters"
// (--no-emitter-light: emissive surfaces light nothing).
std::string referenceLabel(const ReferenceSpec& spec, uint32_t spp, const Options& o);

}  // namespace gi_bench
