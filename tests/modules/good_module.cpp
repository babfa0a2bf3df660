// A valid module registering one effect, "test_good".
#include "test_effect.h"

namespace {
constexpr char kGood[] = "test_good";
}

GI_EFFECT_MODULE(gi::test::NamedEffect<kGood>)
