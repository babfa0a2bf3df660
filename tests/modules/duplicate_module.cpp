// Registers "test_fresh" and then "test_good", the name good_module already registers: loaded
// after it, the whole module must be refused (test_fresh included).
#include "test_effect.h"

namespace {
constexpr char kFresh[] = "test_fresh";
constexpr char kGood[] = "test_good";
}  // namespace

GI_EFFECT_MODULE(gi::test::NamedEffect<kFresh>, gi::test::NamedEffect<kGood>)
