// What an effect's declaration (EffectInfo::reads / writes) promises, checked and used without a
// device: the order effects of one stage run in, and whether the passes an effect added kept
// to what it declared. The renderer applies both on every graph build.
#pragma once

#include <functional>
#include <set>
#include <string>
#include <vector>

#include "gi/effect_info.h"

namespace gi {

// The order (indices into `effects`) in which effects of one stage run: an effect that reads a
// resource another one produces runs after it. A resource an effect both reads and writes (it
// modifies it in place, like "lit") orders nothing, so such effects keep their given order
// among the others. A cycle is a gi::Error naming the effects in it.
std::vector<size_t> orderEffects(const std::vector<const EffectInfo*>& effects);

// Checks what an effect's passes looked up and published on the blackboard against its
// declaration: a look-up of a resource it neither reads nor writes, a published resource it
// does not declare, and (when it published anything) a declared write it did not publish
// (unless `optional(name)`: an input whose neutral fallback may stand in) are gi::Errors naming
// the effect and the resource.
void checkEffectResources(const EffectInfo& info, const std::set<std::string>& lookedUp,
                          const std::set<std::string>& published,
                          const std::function<bool(const std::string&)>& optional);

// What one effect's passes looked up and published on the blackboard in one graph build.
struct EffectPublications {
  std::string effect;
  std::set<std::string> lookedUp, published;
};

// An input of a later stage that makes another reach nothing where it is published: e.g.
// "ambient" replaces the environment term that "ao" multiplies. `resourceDoes` and
// `maskedDoes` say what each does, for the error.
struct Masking {
  std::string resource, resourceDoes, masked, maskedDoes;
};

// Effects in the order their passes were added. Refused, with a gi::Error naming both effects
// and the resource, because one effect's work would reach nothing with no word to the user:
// - an effect publishes a resource an earlier effect published, without looking it up (the
//   earlier version is replaced and the frame graph culls its passes); reading it first (a
//   chain, e.g. filters of "lit") is composition, not loss;
// - an effect publishes a `Masking::resource` while another publishes what it masks, and the
//   masking effect did not look that up (an effect that reads it composes the two itself).
void checkComposition(const std::vector<EffectPublications>& inOrder,
                      const std::vector<Masking>& masks);

}  // namespace gi
