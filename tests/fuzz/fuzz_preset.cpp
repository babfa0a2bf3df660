// Quality presets (assets/presets/*.json) through gi::parsePreset, the body of loadPreset.
#include "fuzz_input.h"
#include "gi/effect_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  gi::fuzz::expectSceneOrError(
      [&] { gi::parsePreset(gi::fuzz::asText(data, size), "fuzz-preset.json"); });
  return 0;
}
