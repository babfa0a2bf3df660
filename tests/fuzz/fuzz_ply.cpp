// PLY (ASCII and binary) through gi::loadScene.
#include "fuzz_input.h"
#include "gi/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = gi::fuzz::writeInput("in.ply", gi::fuzz::asText(data, size));
  gi::fuzz::expectSceneOrError([&] { gi::loadScene(path); });
  return 0;
}
