// libFuzzer target: parseScene on arbitrary bytes parsed as JSON (comments allowed, as loadScene does).
// JSON syntax errors belong to nlohmann-json and are skipped; everything parseScene does with a
// syntactically valid document is under test. An accepted scene must survive sceneToJson -> parseScene
// (checkpoints embed the scene that way) and that round trip must be a fixed point.
#include <nlohmann/json.hpp>

#include "core/scene.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  nlohmann::json j = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false,
                                           /*ignore_comments=*/true);
  if (j.is_discarded()) return 0;
  const std::string file = "fuzz-scene.json";
  fl::Scene s;
  if (!fl::fuzz::expectCleanRejection(file, false, [&] { s = fl::parseScene(j, file, "/nonexistent-base"); }))
    return 0;
  const std::string once = fl::sceneToJson(s);
  fl::Scene again;
  try {
    again = fl::parseScene(nlohmann::json::parse(once), "roundtrip.json");
  } catch (const std::exception& e) {
    fl::fuzz::fail(std::string("an accepted scene does not re-load from sceneToJson: ") + e.what() + "\n" + once);
  }
  if (fl::sceneToJson(again) != once) fl::fuzz::fail("sceneToJson -> parseScene is not a fixed point:\n" + once);
  return 0;
}
