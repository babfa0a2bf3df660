// A module built against another effect ABI: its version is GI_EFFECT_ABI_VERSION + 1. The
// registry must refuse it before calling gi_register_effects.
#include "test_effect.h"

namespace {
constexpr char kBad[] = "test_bad_abi";
}

extern "C" __attribute__((visibility("default"))) uint32_t gi_effect_abi_version() {
  return GI_EFFECT_ABI_VERSION + 1;
}
extern "C" __attribute__((visibility("default"))) void gi_register_effects(
    gi::EffectRegistry& registry) {
  gi::detail::registerAll<gi::test::NamedEffect<kBad>>(registry);
}
