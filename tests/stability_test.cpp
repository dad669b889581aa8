// Numerical stability on stiff and extreme cases (reduced size, for CI; the full suite is a study):
// every case either runs with a bounded energy-balance error and overlaps below the stated fraction of the
// radius, or stops with a clear diagnostic — never a silent NaN. Each guard is triggered by a test.
// The cases are shared with the full-size study (app/stability_cases.hpp, `fabriclab-accuracy --stability`).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "app/stability_cases.hpp"
#include "core/errors.hpp"
#include "core/runner.hpp"

using namespace fl;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

using stability::kEnergyBound;
using stability::kOverlapBound;
using stability::Outcome;
using stability::tryRun;
constexpr int kCount = 400;  // reduced size for CI (the full study uses 4000)

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("fl-stability-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

json base() { return stability::baseScene(kCount); }

// Runs to the end; returns the runner. Any exception propagates.
Runner runAll(const json& j) {
  Runner r(parseScene(j, "stability.json"));
  while (r.advance(5000)) {
  }
  return r;
}

}  // namespace

TEST(StabilitySuite, ExtremeCasesRunBoundedOrStopWithADiagnostic) {
  const fs::path dir = scratch("suite");
  // one glass specimen at 318 kPa, branched into every case
  json prep = base();
  prep["output"]["directory"] = (dir / "prep").string();
  prep["stages"] = stability::preparationStages(0.1);
  Runner prepared = runAll(prep);
  const std::string specimen = prepared.summaries().back().checkpoint;
  ASSERT_TRUE(fs::exists(specimen));

  const std::vector<stability::Case> cases = stability::branchCases();
  ASSERT_EQ(cases.size(), 10u);
  for (const stability::Case& c : cases) {
    SCOPED_TRACE(c.name);
    json j = base();
    j["specimen"] = {{"source", "checkpoint"}, {"path", specimen}};
    j["output"]["directory"] = (dir / c.name).string();
    c.edit(j);
    const Outcome o = tryRun(j);
    if (o.completed) {
      EXPECT_TRUE(o.finite);
      EXPECT_LT(o.maxOverlap, c.overlapLimit);
      EXPECT_LT(o.maxEnergyError, kEnergyBound);
    } else {
      EXPECT_TRUE(c.mayStop) << o.error;
      EXPECT_NE(o.error.find("To fix:"), std::string::npos) << o.error;
    }
    std::printf("[stability] %-24s %s  max overlap/r %.3g  max energy error %.3g %s\n", c.name.c_str(),
                o.completed ? "completed" : "stopped  ", o.maxOverlap, o.maxEnergyError, o.error.substr(0, 120).c_str());
  }
  fs::remove_all(dir);
}

TEST(StabilitySuite, LooseGasAndTenToOneSizeRatio) {
  // a gas with no contacts and no damping: nothing to do but must stay finite and conserve energy
  const Outcome gas = tryRun(stability::looseGasScene(kCount));
  EXPECT_TRUE(gas.completed) << gas.error;
  // 10:1 size ratio compressed to 100 kPa
  const Outcome ratio = tryRun(stability::sizeRatioScene(kCount));
  EXPECT_TRUE(ratio.completed) << ratio.error;
  EXPECT_LT(ratio.maxOverlap, kOverlapBound);
}

TEST(Guards, TimeStepAdaptsWhenContactsStiffen) {
  json j = base();
  j["numerics"]["time_step_factor"] = 1.0;  // the Rayleigh step itself: too large once contacts are loaded
  j["stages"] = json::array({{{"type", "isotropic_compression"}, {"pressure", 10e6}}});
  Runner r = runAll(j);
  EXPECT_GT(r.timeStepChanges(), 0);
  EXPECT_LT(r.simulation().timeStep(), r.simulation().rayleighStep());
  EXPECT_LE(r.simulation().timeStep(), 0.35 * r.simulation().stiffnessTimeStep() * 1.0001);
}

TEST(Guards, BlowUpStopsWithCauseFixAndDiagnosticCheckpoint) {
  const fs::path dir = scratch("blowup");
  json j = base();
  j["guards"] = {{"adaptive_time_step", false}};
  j["numerics"]["time_step_factor"] = 1.0;
  j["numerics"]["local_damping"] = 0.0;
  j["output"]["directory"] = dir.string();
  j["stages"] = json::array({{{"type", "isotropic_compression"}, {"pressure", 10e6}}});
  const Outcome o = tryRun(j);
  ASSERT_FALSE(o.completed) << "expected an instability";
  EXPECT_NE(o.error.find("numerical instability"), std::string::npos) << o.error;
  EXPECT_NE(o.error.find("To fix:"), std::string::npos);
  EXPECT_NE(o.error.find("Diagnostic checkpoint"), std::string::npos);
  bool found = false;
  for (const auto& e : fs::directory_iterator(dir / "checkpoints"))
    found |= e.path().filename().string().rfind("diagnostic-step-", 0) == 0;
  EXPECT_TRUE(found);
  fs::remove_all(dir);
}

TEST(Guards, OverlapBeyondTheLimitStops) {
  json j = base();
  j["material"]["shear_modulus"] = 10e6;  // soft: 1 MPa gives overlaps of several % of the radius
  j["stages"] = json::array({{{"type", "isotropic_compression"}, {"pressure", 1e6}}});
  const Outcome o = tryRun(j);
  ASSERT_FALSE(o.completed);
  EXPECT_NE(o.error.find("overlap"), std::string::npos) << o.error;
  EXPECT_NE(o.error.find("max_overlap_ratio"), std::string::npos);
}

TEST(Guards, LeavingTheQuasiStaticRegimeIsWarned) {
  struct Catch : RunObserver {
    std::vector<std::string> w;
    void onWarning(const std::string& m) override { w.push_back(m); }
  } seen;
  json j = base();
  j["stages"] = json::array({{{"type", "isotropic_compression"}, {"pressure", 50e3}},
                             {{"type", "triaxial"}, {"axial_strain", 0.002}, {"strain_rate", 50}}});
  Runner r(parseScene(j, "warn.json"));
  r.addObserver(&seen);
  while (r.advance(5000)) {
  }
  bool inertial = false;
  for (auto& m : seen.w) inertial |= m.find("inertial number") != std::string::npos;
  EXPECT_TRUE(inertial);
}
