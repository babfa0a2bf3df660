// What gi-bench compares an effect with: the reference renderer's quantity and parameters for
// the quantity an effect declares (gi::EstimatedQuantity, from its current settings) and for
// its physical target (gi::GroundTruth). The cache key text holds every parameter the quantity
// uses, so changing one (the radius, the membership, ...) selects another reference.
#pragma once

#include <string>

#include "gi/effect_info.h"
#include "gi/reference/reference.h"

namespace gi::bench {

struct ReferenceSpec {
  reference::Quantity quantity = reference::Quantity::Direct;
  float radius = 0.5f;  // AO, ao-split, obscurance and Alchemy only
  reference::Membership membership = reference::Membership::Sqrt;  // obscurance only
  reference::AlchemyParams alchemy;                                // Alchemy only
};

// The reference quantity an effect declares. Throws gi::Error(Usage) for an unknown
// membership or a non-finite / non-positive radius.
ReferenceSpec declaredSpec(const EstimatedQuantity& q);
// The physical target: AO of the declared radius (ao-split with `aoSplit`) for AO,
// direct + indirect for indirect light, direct light otherwise.
ReferenceSpec targetSpec(GroundTruth truth, const EstimatedQuantity& declared, bool aoSplit);

// AO, ao-split, obscurance, Alchemy: scalar images read from the effect's "ao" resource.
bool isAoLike(reference::Quantity q);
// "obscurance linear r=0.5", "alchemy r=0.5 sigma=1 u=0 eps=0.0001 k=1", "ao r=0.5", "direct".
std::string label(const ReferenceSpec& s);
// Canonical text of the quantity and the parameters it uses (floats exact, in hex).
std::string keyText(const ReferenceSpec& s);
// Copies quantity and parameters into the reference renderer's settings.
void apply(const ReferenceSpec& s, reference::Settings& settings);

inline bool operator<(const ReferenceSpec& a, const ReferenceSpec& b) {
  return keyText(a) < keyText(b);
}
inline bool operator==(const ReferenceSpec& a, const ReferenceSpec& b) {
  return keyText(a) == keyText(b);
}

}  // namespace gi::bench
