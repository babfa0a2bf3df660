// JSON scene files through gi::loadScene (models they name are looked up next to the file, in
// the fuzzer's own folder, where a one-triangle OBJ "tri.obj" waits).
#include "fuzz_input.h"
#include "gi/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool once =
      (gi::fuzz::writeInput("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), true);
  (void)once;
  const std::string path = gi::fuzz::writeInput("in.json", gi::fuzz::asText(data, size));
  gi::fuzz::expectSceneOrError([&] { gi::loadScene(path); });
  return 0;
}
