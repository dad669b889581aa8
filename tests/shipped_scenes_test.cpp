// Every shipped scene parses, and a reduced version of the paper's specimen preparation runs end to end
// (the full 4000-sphere run is a study, not a CI test) and reports e, Z, Zm and a.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/runner.hpp"

using namespace fl;
namespace fs = std::filesystem;

namespace {
nlohmann::json readJson(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in, nullptr, true, true);
}
}  // namespace

TEST(ShippedScenes, AllParse) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(FL_SOURCE_DIR) / "resources" / "scenes")) {
    if (e.path().extension() != ".json") continue;
    EXPECT_NO_THROW(loadScene(e.path().string())) << e.path();
    ++n;
  }
  EXPECT_GE(n, 16);  // default, the paper specimen, and the paper study (2 specimens, 4 histories, 8 runs)
}

TEST(ShippedScenes, ReducedPaperSpecimenPreparationReportsItsState) {
  auto j = readJson(fs::path(FL_SOURCE_DIR) / "resources/scenes/paper-isotropic-specimen.json");
  j["specimen"]["count"] = 400;               // reduced size
  j["numerics"]["density_scale"] = 100;       // and a larger step: CI checks the pipeline, not the numbers
  j["numerics"]["local_damping"] = 0.1;
  j["numerics"]["threads"] = 1;
  j["servo"]["max_inertial_number"] = 0.02;
  j["servo"]["max_strain_rate"] = 20;
  j["servo"]["unbalanced_tolerance"] = 0.01;
  j["output"]["directory"] = "";
  Runner r(parseScene(j, "paper-isotropic-specimen.json (reduced)"));
  while (r.advance(5000)) {
  }
  ASSERT_EQ(r.summaries().size(), 2u);
  const Sample& s50 = r.summaries()[0].end;
  const Sample& s318 = r.summaries()[1].end;
  EXPECT_NEAR(s50.p / 50e3, 1.0, 2e-3);
  EXPECT_NEAR(s318.p / 318e3, 1.0, 2e-3);
  EXPECT_EQ(s50.friction, 0.01);    // compressed with mu_c (docs/paper-report: the e–mu_c table) ...
  EXPECT_EQ(s318.friction, 0.235);  // ... and consolidated with mu
  // low compression friction gives a dense packing: plausible ranges for e, Z, Zm and the fabric
  EXPECT_GT(s318.voidRatio, 0.45);
  EXPECT_LT(s318.voidRatio, 0.70);
  EXPECT_LE(s318.voidRatio, s50.voidRatio);
  EXPECT_GT(s318.Z, 4.0);
  EXPECT_GE(s318.Zm, s318.Z);
  EXPECT_LT(s318.a2D, 0.15);  // isotropic compression: near-isotropic fabric
  EXPECT_LT(std::abs(s318.a3D), 0.15);
}
