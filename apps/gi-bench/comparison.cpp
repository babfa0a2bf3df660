#include "comparison.h"

#include "gi/errors.h"

namespace gi_bench {

// The first effect with an AO-like declaration or target decides (its "ao" is compared), else
// the first that estimates indirect light, else direct light. `aoSplit`: the AO target is the
// ao-split reference (its value is AO_full).
Comparison comparisonFor(const std::vector<gi::EffectConfig>& effects,
                         const gi::EffectRegistry& registry, bool aoSplit) {
  Comparison c;
  c.declared.quantity = c.target.quantity = ref::Quantity::Direct;
  bool indirect = false;
  for (const auto& e : effects) {
    if (!registry.has(e.name)) continue;
    gi::GroundTruth truth = registry.info(e.name).estimates;
    const gi::EstimatedQuantity q = registry.create(e.name)->estimatedQuantity(e.settings);
    const ReferenceSpec declared = gi::bench::declaredSpec(q);
    const bool aoDeclared = gi::bench::isAoLike(declared.quantity);
    // An AO effect may output light itself under some settings (obscurance's radiance
    // transfer publishes the ambient light): it declares a light quantity, and is then judged
    // as light. A light effect that declares AO has no "ao" to read: an error.
    if (!aoDeclared && truth == gi::GroundTruth::AmbientOcclusion)
      truth = declared.quantity == ref::Quantity::Direct ? gi::GroundTruth::DirectLight
                                                         : gi::GroundTruth::IndirectLight;
    if (aoDeclared != (truth == gi::GroundTruth::AmbientOcclusion))
      throw gi::Error(gi::ErrorKind::InvalidData, e.name,
                      "the effect's estimatedQuantity (" + gi::bench::label(declared) +
                          ") is AO-like but its ground truth (info().estimates) is light");
    if (aoDeclared) {
      c.resource = gi::resources::kAO;
      c.declared = declared;
      // The ao-split reference's value is AO bit for bit: one reference serves both scores.
      if (aoSplit && declared.quantity == ref::Quantity::AO)
        c.declared.quantity = ref::Quantity::AOSplit;
      c.target = gi::bench::targetSpec(truth, q, aoSplit);
      c.effect = e.name;
      return c;
    }
    if (!indirect && (truth == gi::GroundTruth::IndirectLight ||
                      declared.quantity == ref::Quantity::DirectIndirect)) {
      indirect = true;
      c.declared = declared;
      c.target = gi::bench::targetSpec(gi::GroundTruth::IndirectLight, q, false);
      c.effect = e.name;
    }
  }
  return c;
}

// --target: the lit image against one light quantity, whatever the effects estimate (an AO
// effect is then judged by the lighting it modulates). An AO-like declaration cannot be read
// from the lit image: its declared score becomes the target's.
Comparison litAgainst(Comparison c, ref::Quantity target) {
  c.resource = gi::resources::kLit;
  c.target = ReferenceSpec{};
  c.target.quantity = target;
  if (gi::bench::isAoLike(c.declared.quantity)) c.declared = c.target;
  return c;
}

// Direct+indirect references also name their bounces (--ref-bounces) and "dark-emitters"
// (--no-emitter-light: emissive surfaces light nothing).
std::string referenceLabel(const ReferenceSpec& spec, uint32_t spp, const Options& o) {
  const bool light = spec.quantity == ref::Quantity::DirectIndirect;
  return gi::bench::label(spec) + " spp=" + std::to_string(spp) +
         (light && o.refBounces > 1 ? " bounces=" + std::to_string(o.refBounces) : "") +
         (light && !o.emitterLight ? " dark-emitters" : "");
}

}  // namespace gi_bench
