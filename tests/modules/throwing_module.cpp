// A module whose effect's constructor throws while the registry probes it: built twice, throwing
// an int (THROWS_INT) or a std::runtime_error. The registry must turn either into an error that
// names the module (tests/test_config_registry.cpp).
#include <stdexcept>

#include "test_effect.h"

namespace {

constexpr char kName[] = "test_throwing";

class Throwing : public gi::test::NamedEffect<kName> {
 public:
  Throwing() {
#if THROWS_INT
    throw 42;
#else
    throw std::runtime_error("the GPU is on fire");
#endif
  }
};

}  // namespace

GI_EFFECT_MODULE(Throwing)
