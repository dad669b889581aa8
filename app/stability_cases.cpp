#include "stability_cases.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/errors.hpp"
#include "core/measurements.hpp"
#include "core/runner.hpp"
#include "core/scene.hpp"

namespace fl::stability {

using nlohmann::json;

json baseScene(int count) {
  json j = json::parse(R"({
    "specimen": {"count": 400, "solid_fraction": 0.3, "seed": 3},
    "numerics": {"time_step_factor": 0.3, "local_damping": 0.1, "density_scale": 100, "threads": 1},
    "servo": {"max_strain_rate": 20, "max_inertial_number": 0.02, "unbalanced_tolerance": 0.01},
    "output": {"sample_interval": 500, "checkpoint_at_stage_end": true},
    "stages": []
  })");
  j["specimen"]["count"] = count;
  return j;
}

json preparationStages(double muC) {
  return json::array({{{"type", "isotropic_compression"}, {"pressure", 318e3}, {"friction", muC}, {"friction_after", 0.235}}});
}

std::vector<Case> branchCases() {
  auto cyc = [](double rate) {
    return json{{"type", "cyclic"}, {"drainage", "undrained"}, {"amplitude", 2.3e-4}, {"cycles", 1}, {"strain_rate", rate}};
  };
  auto iso = [](double p) { return json{{"type", "isotropic_compression"}, {"pressure", p}}; };
  return {
      {"glass x10 stiffer", [=](json& j) { j["material"]["shear_modulus"] = 286.88e9; j["stages"] = {iso(318e3), cyc(1)}; }},
      {"glass x100 stiffer", [=](json& j) { j["material"]["shear_modulus"] = 2868.8e9; j["stages"] = {iso(318e3), cyc(1)}; }},
      // soft: at 50 kPa the overlaps are ~6.5 % of the radius (SC estimate), beyond the default guard ...
      {"very soft G = 10 MPa", [=](json& j) { j["material"]["shear_modulus"] = 10e6; j["stages"] = {iso(50e3), cyc(1)}; }, true},
      // ... and with the guard raised on purpose the run completes with bounded energy error
      {"very soft, limit 0.15",
       [=](json& j) {
         j["material"]["shear_modulus"] = 10e6;
         j["guards"] = {{"max_overlap_ratio", 0.15}};
         j["stages"] = {iso(50e3), cyc(1)};
       },
       false, 0.15},
      {"1 kPa", [=](json& j) { j["stages"] = {iso(1e3), cyc(1)}; }},
      {"10 MPa (jammed dense)", [=](json& j) { j["stages"] = {iso(10e6), cyc(1)}; }},
      {"mu = 0", [=](json& j) { j["material"]["friction"] = 0.0; j["stages"] = {iso(318e3), cyc(1)}; }},
      {"mu = 1", [=](json& j) { j["material"]["friction"] = 1.0; j["stages"] = {iso(318e3), cyc(1)}; }},
      {"no damping", [=](json& j) { j["numerics"]["local_damping"] = 0.0; j["stages"] = {cyc(1)}; }},
      {"high strain rate", [=](json& j) { j["stages"] = {cyc(100)}; }},
  };
}

json looseGasScene(int count) {
  json g = baseScene(count);
  g["numerics"]["local_damping"] = 0.0;
  g["stages"] = json::array({{{"type", "hold"}, {"steps", 3000}}});
  return g;
}

json sizeRatioScene(int count) {
  json s = baseScene(count);
  s["specimen"]["diameters"] = {0.2e-3, 2e-3};
  s["specimen"]["fractions"] = {0.9, 0.1};
  s["stages"] = json::array({{{"type", "isotropic_compression"}, {"pressure", 100e3}}});
  return s;
}

namespace {
// Watches the samples (also those of a run that later stops): energy error, finiteness.
struct Watch final : RunObserver {
  Outcome* o;
  explicit Watch(Outcome* out) : o(out) {}
  void onSample(const Sample& s) override {
    o->maxEnergyError = std::max(o->maxEnergyError, s.energyError);
    o->finite = o->finite && std::isfinite(s.p) && std::isfinite(s.q) && std::isfinite(s.voidRatio);
  }
};
}  // namespace

Outcome tryRun(const json& scene, long probeEvery) {
  Outcome o;
  const auto t0 = std::chrono::steady_clock::now();
  Watch watch(&o);
  o.minDtOverRayleigh = 1e300;
  auto probe = [&](const Simulation& sim, long startStep) {
    o.maxOverlap = std::max(o.maxOverlap, sim.diagnostics().maxOverlapRatio);
    o.steps = sim.stepCount() - startStep;
    const double ratio = sim.timeStep() / sim.rayleighStep();
    o.minDtOverRayleigh = std::min(o.minDtOverRayleigh, ratio);
    o.maxDtOverRayleigh = std::max(o.maxDtOverRayleigh, ratio);
    const double margin = sim.timeStep() / sim.stiffnessTimeStep();
    if (std::isfinite(margin)) o.maxDtOverCritical = std::max(o.maxDtOverCritical, margin);
    o.finalPressure = stressMeasures(sim.contactStress()).p;
  };
  try {
    Runner r(parseScene(scene, "stability.json"));
    r.addObserver(&watch);
    const long startStep = r.simulation().stepCount();
    bool more = true;
    try {
      while (more) {
        more = r.advance(probeEvery);
        probe(r.simulation(), startStep);
        o.timeStepChanges = r.timeStepChanges();
      }
    } catch (const InstabilityError&) {
      probe(r.simulation(), startStep);  // the state at the stop
      o.timeStepChanges = r.timeStepChanges();
      throw;
    }
    o.completed = true;
  } catch (const InstabilityError& e) {
    o.error = e.what();
  }
  if (o.minDtOverRayleigh > o.maxDtOverRayleigh) o.minDtOverRayleigh = o.maxDtOverRayleigh;
  o.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

}  // namespace fl::stability
