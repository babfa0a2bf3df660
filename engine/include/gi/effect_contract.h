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

}  // namespace gi
