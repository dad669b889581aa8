// libFuzzer target: loadScene on arbitrary bytes written to a file (the path a user's hand-edited scene takes:
// file reading, JSON parsing with comments, validation).
#include "core/scene.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = fl::fuzz::scratchPath("scene");
  fl::fuzz::writeScratch(path, data, size);
  fl::fuzz::expectCleanRejection(path, false, [&] { (void)fl::loadScene(path); });
  return 0;
}
