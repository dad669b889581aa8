// Scene files: defaults from the schema, the reference document, and one test per error kind, each
// checking that the message names the file, the field and what is allowed.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/scene.hpp"

using namespace fl;
using nlohmann::json;

namespace {
json minimal() {
  return json::parse(R"({"stages": [{"type": "isotropic_compression", "pressure": 50000}]})");
}
// Expects parseScene to throw InputError whose message contains every fragment.
void expectError(const json& j, std::initializer_list<std::string> fragments) {
  try {
    parseScene(j, "scenes/test.json");
    ADD_FAILURE() << "accepted: " << j.dump();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("scenes/test.json"), std::string::npos) << m;
    for (const auto& f : fragments) EXPECT_NE(m.find(f), std::string::npos) << "missing '" << f << "' in: " << m;
  }
}
}  // namespace

TEST(SceneFile, DefaultsComeFromTheSchema) {
  const Scene s = parseScene(minimal(), "x.json");
  EXPECT_NEAR(s.material.shearModulus(), 28.688e9, 1.0);
  EXPECT_EQ(s.material.poissonRatio, 0.22);
  EXPECT_EQ(s.specimen.gas.count, 4000);
  EXPECT_EQ(s.specimen.gas.sizes.diameters.size(), 7u);
  EXPECT_EQ(s.numerics.timeStepFactor, 0.25);
  ASSERT_EQ(s.stages.size(), 1u);
  EXPECT_EQ(s.stages[0].type, StageType::IsotropicCompression);
  EXPECT_EQ(s.stages[0].pressure, 50000);
  EXPECT_EQ(s.stages[0].friction, -1.0);  // absent: unchanged
}

TEST(SceneFile, ResolvedSceneRoundTrips) {
  json j = minimal();
  j["stages"].push_back({{"type", "cyclic"}, {"drainage", "undrained"}, {"amplitude", 2.3e-4}, {"cycles", 3}});
  j["stages"].push_back({{"type", "k0"}, {"until_isotropic", true}});
  j["stages"].push_back({{"type", "prestrain"}, {"axial_strain", 0.1}, {"pressure", 50e3}});
  const Scene a = parseScene(j, "x.json");
  EXPECT_EQ(a.stages.size(), 5u);  // prestrain expands into shear + re-consolidation
  const Scene b = parseScene(json::parse(sceneToJson(a)), "y.json");
  EXPECT_EQ(sceneToJson(a), sceneToJson(b));
}

TEST(SceneFile, ReferenceDocumentListsEveryField) {
  const std::string doc = sceneReferenceMarkdown();
  for (const auto& f : sceneSchema()) EXPECT_NE(doc.find("`" + f.key + "`"), std::string::npos) << f.key;
  EXPECT_NE(doc.find("time_step_factor"), std::string::npos);
}

TEST(SceneErrors, OutOfRange) {
  json j = minimal();
  j["numerics"] = {{"time_step_factor", 2.0}};
  expectError(j, {"numerics.time_step_factor", "(0, 1]"});
}

TEST(SceneErrors, WrongType) {
  json j = minimal();
  j["specimen"] = {{"count", "many"}};
  expectError(j, {"specimen.count", "integer"});
}

TEST(SceneErrors, NonIntegerInteger) {
  json j = minimal();
  j["specimen"] = {{"count", 10.5}};
  expectError(j, {"specimen.count", "integer"});
}

TEST(SceneErrors, UnknownField) {
  json j = minimal();
  j["material"] = {{"youngs", 1e9}};
  expectError(j, {"material.youngs", "allowed", "shear_modulus"});
}

TEST(SceneErrors, UnknownSection) {
  json j = minimal();
  j["solver"] = json::object();
  expectError(j, {"solver", "allowed"});
}

TEST(SceneErrors, UnknownStageType) {
  json j = minimal();
  j["stages"].push_back({{"type", "shear_box"}});
  expectError(j, {"stages[1].type", "shear_box", "cyclic"});
}

TEST(SceneErrors, MissingRequiredStageField) {
  json j = minimal();
  j["stages"].push_back({{"type", "cyclic"}, {"cycles", 3}});
  expectError(j, {"stages[1].amplitude", "required"});
}

TEST(SceneErrors, BadChoice) {
  json j = minimal();
  j["stages"].push_back({{"type", "triaxial"}, {"axial_strain", 0.01}, {"drainage", "partly"}});
  expectError(j, {"stages[1].drainage", "drained", "undrained"});
}

TEST(SceneErrors, K0NeedsExactlyOneTarget) {
  json j = minimal();
  j["stages"].push_back({{"type", "k0"}, {"pressure", 1e5}, {"axial_stress", 2e5}});
  expectError(j, {"stages[1]", "exactly one"});
}

TEST(SceneErrors, SizeDistributionMismatch) {
  json j = minimal();
  j["specimen"] = {{"diameters", {1e-3, 2e-3}}, {"fractions", {1.0}}};
  expectError(j, {"specimen", "fractions"});
}

TEST(SceneErrors, FileSourceNeedsAPath) {
  json j = minimal();
  j["specimen"] = {{"source", "checkpoint"}};
  expectError(j, {"specimen.path", "required"});
}

TEST(SceneErrors, NotJsonNamesTheFile) {
  EXPECT_THROW(loadScene("/nonexistent/scene.json"), IoError);
}

TEST(SceneFile, CommittedReferenceDocumentIsCurrent) {
  // docs/scene-reference.md is generated from the schema; regenerate with `fabriclab-run --schema-doc FILE`
  std::ifstream in(std::string(FL_SOURCE_DIR) + "/docs/scene-reference.md");
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(doc, sceneReferenceMarkdown()) << "run: fabriclab-run --schema-doc docs/scene-reference.md";
}
