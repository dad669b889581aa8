// The numerical-stability suite's cases, shared by the reduced CI test (tests/stability_test.cpp, 400
// spheres) and the full-size study (`fabriclab-accuracy --stability`, 4000 spheres, docs/stability.md), so
// both run exactly the same scenes at different sizes.
// Each case either runs with a bounded energy-balance error and overlaps below the stated fraction of the
// radius, or stops with a diagnostic (fl::InstabilityError whose message says "To fix:") — never a silent
// NaN. Cases are scene edits (JSON) applied to baseScene(); the branch cases start from a prepared
// specimen checkpoint at 318 kPa.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace fl::stability {

constexpr double kOverlapBound = 0.05;  // stated bound: overlaps below 5 % of the smaller radius [-]
constexpr double kEnergyBound = 0.05;   // stated bound on the energy-balance error of a completed case [-]

// The suite's numerics: glass, gas of `count` spheres (solid fraction 0.3, seed 3), time_step_factor 0.3,
// local damping 0.1, density scale 100, one thread, fast servo; no stages.
nlohmann::json baseScene(int count);

// Isotropic compression of the gas to 318 kPa with compression friction muC, then mu = 0.235: the specimen
// every branch case starts from. muC = 0.1 is the suite's standard specimen; muC = 0 gives the densest
// (jammed, frictionless-compressed) state.
nlohmann::json preparationStages(double muC);

struct Case {
  std::string name;
  std::function<void(nlohmann::json&)> edit;  // sets stages and the changed fields
  bool mayStop = false;        // allowed to stop with a diagnostic instead of completing
  double overlapLimit = kOverlapBound;  // bound on max overlap / r when it completes [-]
};
// The cases that branch from a prepared specimen (set scene["specimen"] to the checkpoint first):
// stiff x10/x100, very soft (with and without a raised overlap guard), 1 kPa, 10 MPa, mu 0 and 1, no
// damping, high strain rate.
std::vector<Case> branchCases();

// Cases that start from a gas of `count` spheres: a loose gas with no contacts and no damping (hold), and
// a 10:1 size ratio compressed to 100 kPa.
nlohmann::json looseGasScene(int count);
nlohmann::json sizeRatioScene(int count);

struct Outcome {
  bool completed = false;
  std::string error;           // the InstabilityError message when stopped
  double maxOverlap = 0;       // max delta / r seen at the probed steps [-]
  double maxEnergyError = 0;   // max energy-balance error over the samples [-]
  bool finite = true;          // p, q, e finite in every sample
  long steps = 0;              // steps run
  double wallSeconds = 0;      // [s]
  double minDtOverRayleigh = 0, maxDtOverRayleigh = 0;  // dt used / Rayleigh step over the samples [-]
  double maxDtOverCritical = 0;  // max dt / stiffness-based critical step over the samples [-]
  double finalPressure = 0;    // p' at the end [Pa]
  long timeStepChanges = 0;
};
// Runs a scene to its end, probing the overlap every `probeEvery` steps. Catches only InstabilityError
// (the diagnostic stop); anything else propagates.
Outcome tryRun(const nlohmann::json& scene, long probeEvery = 200);

}  // namespace fl::stability
