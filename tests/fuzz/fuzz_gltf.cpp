// glTF 2.0 (.gltf JSON or .glb binary, chosen by the 'glTF' magic) through gi::loadScene, so
// that the checks after loading (bounds, framing) run too.
#include "fuzz_input.h"
#include "gi/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes = gi::fuzz::asText(data, size);
  const bool glb = bytes.substr(0, 4) == "glTF";
  const std::string path = gi::fuzz::writeInput(glb ? "in.glb" : "in.gltf", bytes);
  gi::fuzz::expectSceneOrError([&] { gi::loadScene(path); });
  return 0;
}
