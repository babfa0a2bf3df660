// OBJ and its material library: the input up to a line "#MTL" is in.obj, the rest in.mtl
// (seeds append their .mtl so); "mtllib in.mtl" in the OBJ part reads it.
#include "fuzz_input.h"
#include "gi/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes = gi::fuzz::asText(data, size);
  const size_t split = bytes.find("\n#MTL\n");
  const std::string path = gi::fuzz::writeInput("in.obj", bytes.substr(0, split));
  gi::fuzz::writeInput(
      "in.mtl", split == std::string_view::npos ? std::string_view() : bytes.substr(split + 6));
  gi::fuzz::expectSceneOrError([&] { gi::loadScene(path); });
  return 0;
}
