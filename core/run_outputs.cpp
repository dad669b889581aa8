#include "run_outputs.hpp"

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

namespace fl {

namespace {
std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
std::string g(double v) { return fmt("%.10g", v); }

nlohmann::json sampleJson(const Sample& s) {
  return {{"step", s.step},           {"time_s", s.time},       {"sxx_Pa", s.stress.x()}, {"syy_Pa", s.stress.y()},
          {"szz_Pa", s.stress.z()},   {"p_Pa", s.p},            {"q_Pa", s.q},            {"eps_a", s.epsA},
          {"eps_v", s.epsV},          {"void_ratio", s.voidRatio}, {"Z", s.Z},           {"Zm", s.Zm},
          {"a_2D_RB", s.a2D},         {"a_3D", s.a3D},          {"du_Pa", s.du},          {"inertial_number", s.inertialNumber},
          {"unbalanced_force_ratio", s.unbalanced}, {"energy_balance_error", s.energyError},
          {"time_step_s", s.timeStep}, {"time_step_margin", s.timeStepMargin}, {"friction", s.friction}};
}
}  // namespace

std::string RunOutputs::timeSeriesHeader() {
  return "step,time_s,stage,cycle,sxx_Pa,syy_Pa,szz_Pa,p_Pa,q_Pa,tau_Pa,eps_a,eps_r,eps_v,gamma,void_ratio,Z,Zm,"
         "a_3D,a_2D_RB,du_Pa,inertial_number,unbalanced_force_ratio,kinetic_J,elastic_J,dissipated_J,"
         "boundary_work_J,energy_balance_error,time_step_s,time_step_margin,friction";
}

std::string RunOutputs::timeSeriesRow(const Sample& s) {
  std::string r = std::to_string(s.step) + "," + g(s.time) + "," + std::to_string(s.stage) + "," +
                  std::to_string(s.cycle);
  for (double v : {s.stress.x(), s.stress.y(), s.stress.z(), s.p, s.q, s.tau, s.epsA, s.epsR, s.epsV, s.gamma,
                   s.voidRatio, s.Z, s.Zm, s.a3D, s.a2D, s.du, s.inertialNumber, s.unbalanced, s.kinetic, s.elastic,
                   s.dissipated, s.boundaryWork, s.energyError, s.timeStep, s.timeStepMargin, s.friction})
    r += "," + g(v);
  return r;
}

std::string RunOutputs::cycleHeader() {
  return "cycle,G_sec_Pa,E_sec_Pa,damping_ratio,tau_min_Pa,tau_max_Pa,p_min_Pa,p_max_Pa,du_min_Pa,du_max_Pa,"
         "du_end_Pa,gamma_min,gamma_max,eps_v_end,Z_end,Zm_end,a_3D_end,a_2D_RB_end,void_ratio_end,failed";
}

std::string RunOutputs::cycleRow(const CycleRecord& c) {
  std::string r = std::to_string(c.cycle);
  for (double v : {c.Gsec, c.Esec, c.damping, c.tauMin, c.tauMax, c.pMin, c.pMax, c.duMin, c.duMax, c.duEnd,
                   c.gammaMin, c.gammaMax, c.end.epsV, c.end.Z, c.end.Zm, c.end.a3D, c.end.a2D, c.end.voidRatio})
    r += "," + g(v);
  return r + (c.failed ? ",1" : ",0");
}

RunOutputs::RunOutputs(const std::string& directory, const Scene& scene)
    : m_dir(directory),
      m_series((std::filesystem::path(directory) / "timeseries.csv").string(), timeSeriesHeader()),
      m_cycles((std::filesystem::path(directory) / "cycles.csv").string(), cycleHeader()),
      m_warnings((std::filesystem::path(directory) / "warnings.txt").string(), "# run-time warnings"),
      m_sceneName(scene.name) {
  writeFileAtomically((std::filesystem::path(directory) / "scene.json").string(), sceneToJson(scene) + "\n");
}

void RunOutputs::onSample(const Sample& s) { m_series.append(timeSeriesRow(s)); }
void RunOutputs::onCycle(const CycleRecord& c) { m_cycles.append(cycleRow(c)); }
void RunOutputs::onWarning(const std::string& message) { m_warnings.append(message); }

void RunOutputs::onStageEnd(const StageSummary& s) {
  m_stages.push_back(s);
  writeFileAtomically((std::filesystem::path(m_dir) / "stages.json").string(), stageSummariesJson(m_sceneName, m_stages));
}

std::string stageSummariesJson(const std::string& sceneName, const std::vector<StageSummary>& stages) {
  nlohmann::json j;
  j["scene"] = sceneName;
  j["stages"] = nlohmann::json::array();
  for (const StageSummary& s : stages)
    j["stages"].push_back({{"index", s.index},
                           {"name", s.name},
                           {"type", s.type},
                           {"steps", s.steps},
                           {"wall_seconds", s.seconds},
                           {"K0", s.K0},
                           {"OCR", s.ocr},
                           {"checkpoint", s.checkpoint},
                           {"end", sampleJson(s.end)}});
  return j.dump(2) + "\n";
}

}  // namespace fl
