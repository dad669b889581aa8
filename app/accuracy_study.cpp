#include "accuracy_study.hpp"

#include <time.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/measurements.hpp"
#include "core/runner.hpp"
#include "core/scene.hpp"

namespace fl::accuracy {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
// "0.35 %", "12 %", "n/a"
std::string pct(double e) {
  if (!std::isfinite(e)) return "n/a";
  const double p = 100.0 * e;
  if (p == 0) return "0";
  if (p < 0.01) return fmt("%.1e %%", p);
  if (p < 10) return fmt("%.2f %%", p);
  return fmt("%.0f %%", p);
}
std::string num(double v) {  // compact value of a rung
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
std::string secs(double s) { return s < 100 ? fmt("%.1f s", s) : fmt("%.0f s", s); }

const Factor kFactors[] = {Factor::InertialNumber, Factor::TimeStepFactor, Factor::LocalDamping,
                           Factor::Restitution,    Factor::DensityScale,   Factor::ParticleCount};
const Drainage kDrainages[] = {Drainage::Undrained, Drainage::Drained};
}  // namespace

// ---- names ---------------------------------------------------------------------------------------------
const char* factorKey(Factor f) {
  switch (f) {
    case Factor::InertialNumber: return "inertial_number";
    case Factor::TimeStepFactor: return "time_step_factor";
    case Factor::LocalDamping: return "local_damping";
    case Factor::Restitution: return "restitution";
    case Factor::DensityScale: return "density_scale";
    case Factor::ParticleCount: return "particle_count";
  }
  return "?";
}
const char* factorTitle(Factor f) {
  switch (f) {
    case Factor::InertialNumber: return "inertial number I (strain rate)";
    case Factor::TimeStepFactor: return "time_step_factor (dt / Rayleigh step)";
    case Factor::LocalDamping: return "local damping alpha";
    case Factor::Restitution: return "contact damping (restitution e)";
    case Factor::DensityScale: return "density scaling (fixed physical strain rate)";
    case Factor::ParticleCount: return "particle count (size effect)";
  }
  return "?";
}
bool isNumerical(Factor f) { return f != Factor::ParticleCount; }
bool isExactLimit(Factor f, double v) {
  return (f == Factor::LocalDamping && v == 0.0) || (f == Factor::Restitution && v == 1.0) ||
         (f == Factor::DensityScale && v == 1.0);
}
const char* drainageKey(Drainage d) { return d == Drainage::Undrained ? "undrained" : "drained"; }

const char* outputKey(Output o) {
  switch (o) {
    case Output::Gsec: return "G_sec";
    case Output::PReversal: return "p_rev";
    case Output::QReversal: return "q_rev";
    case Output::Du: return "du";
    case Output::EpsV: return "eps_v";
    case Output::Z: return "Z";
    case Output::A: return "a";
    default: return "?";
  }
}
const char* outputTitle(Output o) {
  switch (o) {
    case Output::Gsec: return "G_sec per cycle";
    case Output::PReversal: return "p' at reversals";
    case Output::QReversal: return "q at reversals";
    case Output::Du: return "Δu at cycle ends";
    case Output::EpsV: return "ε_v at cycle ends";
    case Output::Z: return "Z at cycle ends";
    case Output::A: return "a (a_2D) at cycle ends";
    default: return "?";
  }
}
bool appliesTo(Output o, Drainage d) {
  if (o == Output::Du) return d == Drainage::Undrained;
  if (o == Output::EpsV) return d == Drainage::Drained;
  return true;
}

double Settings::value(Factor f) const {
  switch (f) {
    case Factor::InertialNumber: return inertialNumber;
    case Factor::TimeStepFactor: return timeStepFactor;
    case Factor::LocalDamping: return localDamping;
    case Factor::Restitution: return restitution;
    case Factor::DensityScale: return densityScale;
    case Factor::ParticleCount: return particles;
  }
  return kNaN;
}
void Settings::set(Factor f, double v) {
  switch (f) {
    case Factor::InertialNumber: inertialNumber = v; break;
    case Factor::TimeStepFactor: timeStepFactor = v; break;
    case Factor::LocalDamping: localDamping = v; break;
    case Factor::Restitution: restitution = v; break;
    case Factor::DensityScale: densityScale = v; break;
    case Factor::ParticleCount: particles = static_cast<int>(std::lround(v)); break;
  }
}
namespace {
bool sameSettings(const Settings& a, const Settings& b) {
  return a.inertialNumber == b.inertialNumber && a.timeStepFactor == b.timeStepFactor && a.localDamping == b.localDamping &&
         a.restitution == b.restitution && a.densityScale == b.densityScale && a.particles == b.particles &&
         a.strainRate == b.strainRate;
}
}  // namespace

const std::vector<double>& Metrics::of(Output o) const {
  switch (o) {
    case Output::Gsec: return Gsec;
    case Output::PReversal: return pReversal;
    case Output::QReversal: return qReversal;
    case Output::Du: return du;
    case Output::EpsV: return epsV;
    case Output::Z: return Z;
    default: return a;
  }
}
std::vector<double>& Metrics::of(Output o) { return const_cast<std::vector<double>&>(static_cast<const Metrics&>(*this).of(o)); }

// ---- configurations --------------------------------------------------------------------------------------
StudyConfig fullConfig() {
  StudyConfig c;
  c.base = Settings{};  // the paper's cyclic numerics: I 1e-4, time_step_factor 0.25, local damping 0.05
  c.base.particles = 2000;
  c.cycles = 2;
  c.ladders = {
      {Factor::InertialNumber, {1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5}},
      {Factor::TimeStepFactor, {0.5, 0.35, 0.25, 0.15, 0.1}},
      {Factor::LocalDamping, {0.3, 0.1, 0.05, 0.0}},
      {Factor::Restitution, {0.5, 0.9, 1.0}},
      {Factor::DensityScale, {1000, 100, 10, 1}},
      {Factor::ParticleCount, {500, 1000, 2000, 4000, 8000}},
  };
  return c;
}

StudyConfig quickConfig() {
  StudyConfig c;
  c.quick = true;
  c.base.particles = 400;
  c.base.inertialNumber = 1e-3;
  c.cycles = 1;
  c.ladders = {
      {Factor::InertialNumber, {1e-2, 3e-3, 1e-3, 3e-4}},
      {Factor::TimeStepFactor, {0.5, 0.25}},
      {Factor::ParticleCount, {300, 400}},
  };
  return c;
}

// ---- pure functions --------------------------------------------------------------------------------------
double relativeError(const std::vector<double>& v, const std::vector<double>& ref) {
  if (v.empty() || v.size() != ref.size()) return kNaN;
  double num = 0, den = 0;
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v[k]) || !std::isfinite(ref[k])) return kNaN;
    num = std::max(num, std::abs(v[k] - ref[k]));
    den = std::max(den, std::abs(ref[k]));
  }
  return den > 0 ? num / den : kNaN;
}

std::vector<std::size_t> paretoFront(const std::vector<double>& cost, const std::vector<double>& error) {
  std::vector<std::size_t> idx;
  for (std::size_t k = 0; k < std::min(cost.size(), error.size()); ++k)
    if (std::isfinite(cost[k]) && std::isfinite(error[k])) idx.push_back(k);
  // by cost, then error; a point is on the front when its error is below every cheaper point's
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return cost[a] != cost[b] ? cost[a] < cost[b] : (error[a] != error[b] ? error[a] < error[b] : a < b);
  });
  std::vector<std::size_t> front;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k : idx) {
    if (error[k] < best) {
      front.push_back(k);
      best = error[k];
    }
  }
  return front;
}

void evaluate(StudyResult& r, const std::function<int(Factor, double, Drainage)>& runIndex) {
  r.rows.clear();
  r.convergence.clear();
  const StudyConfig& c = r.config;
  for (const Ladder& l : c.ladders) {
    if (l.values.empty()) continue;
    for (Drainage d : kDrainages) {
      const int ref = runIndex(l.factor, l.values.back(), d);
      const Metrics& refM = r.runs.at(ref).metrics;
      for (double v : l.values) {
        Row row;
        row.factor = l.factor;
        row.value = v;
        row.drainage = d;
        row.run = runIndex(l.factor, v, d);
        row.reference = v == l.values.back();
        row.base = v == c.base.value(l.factor);
        const RunResult& run = r.runs.at(row.run);
        for (int o = 0; o < kOutputCount; ++o)
          row.errors[o] = appliesTo(Output(o), d) && run.ok && r.runs.at(ref).ok
                              ? relativeError(run.metrics.of(Output(o)), refM.of(Output(o)))
                              : kNaN;
        r.rows.push_back(row);
      }
      if (l.values.size() < 2) continue;
      const int second = runIndex(l.factor, l.values[l.values.size() - 2], d);
      for (int o = 0; o < kOutputCount; ++o) {
        if (!appliesTo(Output(o), d)) continue;
        Convergence cv{l.factor, d, Output(o), l.values.back(), l.values[l.values.size() - 2], kNaN, false, false};
        const bool bothRan = r.runs.at(second).ok && r.runs.at(ref).ok;
        if (bothRan) cv.disagreement = relativeError(r.runs.at(second).metrics.of(Output(o)), refM.of(Output(o)));
        cv.exactLimit = isExactLimit(l.factor, l.values.back());
        cv.converged = r.runs.at(ref).ok && ((cv.exactLimit && !r.runs.at(ref).metrics.of(Output(o)).empty()) ||
                                             (std::isfinite(cv.disagreement) && cv.disagreement <= c.convergenceTolerance));
        r.convergence.push_back(cv);
      }
    }
  }
}

namespace {
const Row* findRow(const StudyResult& r, Factor f, double v, Drainage d) {
  for (const Row& row : r.rows)
    if (row.factor == f && row.value == v && row.drainage == d) return &row;
  return nullptr;
}
const Convergence* findConvergence(const StudyResult& r, Factor f, Drainage d, Output o) {
  for (const Convergence& c : r.convergence)
    if (c.factor == f && c.drainage == d && c.output == o) return &c;
  return nullptr;
}
}  // namespace

Cheapest cheapestBelow(const StudyResult& r, Output output, const std::vector<Drainage>& drainages) {
  Cheapest best;
  for (const Ladder& l : r.config.ladders) {
    if (!isNumerical(l.factor)) continue;
    bool converged = true;
    double refWall = 0;
    for (Drainage d : drainages) {
      const Convergence* cv = findConvergence(r, l.factor, d, output);
      converged = converged && cv && cv->converged;
      const Row* refRow = findRow(r, l.factor, l.values.back(), d);
      if (refRow) refWall += r.runs.at(refRow->run).wallSeconds;
    }
    if (!converged) continue;
    for (double v : l.values) {
      double wall = 0, steps = 0, worst = 0;
      bool ok = true;
      for (Drainage d : drainages) {
        const Row* row = findRow(r, l.factor, v, d);
        if (!row || !(row->errors[int(output)] < r.config.target)) {
          ok = false;
          break;
        }
        wall += r.runs.at(row->run).wallSeconds;
        steps += double(r.runs.at(row->run).particleSteps);
        worst = std::max(worst, row->errors[int(output)]);
      }
      if (!ok) continue;
      if (!best.found || steps < best.particleSteps || (steps == best.particleSteps && worst < best.worstError))
        best = {true, l.factor, v, steps, wall, worst, refWall};
    }
  }
  return best;
}

int runWithSettings(const StudyResult& r, const Settings& s, Drainage d) {
  for (const RunResult& run : r.runs)
    if (run.drainage == d && sameSettings(run.settings, s)) return run.id;
  return -1;
}

int baseRun(const StudyResult& r, Drainage d) { return runWithSettings(r, r.config.base, d); }

std::vector<double> extrapolatedReference(const StudyResult& r, Output output, Drainage d) {
  const int b = baseRun(r, d);
  if (b < 0 || !r.runs.at(b).ok) return {};
  const std::vector<double>& xb = r.runs.at(b).metrics.of(output);
  std::vector<double> x = xb;
  for (const Ladder& l : r.config.ladders) {
    if (!isNumerical(l.factor) || l.values.empty()) continue;
    const int ref = runWithSettings(r, rungSettings(r.config, l.factor, l.values.back(), r.fixedRate), d);
    if (ref < 0 || !r.runs.at(ref).ok) return {};
    const std::vector<double>& xr = r.runs.at(ref).metrics.of(output);
    if (xr.size() != x.size()) return {};
    for (std::size_t k = 0; k < x.size(); ++k) x[k] -= xb[k] - xr[k];
  }
  return x;
}

Combination cheapestCombination(const StudyResult& r, Output output, const std::vector<Drainage>& drainages) {
  Combination best;
  const StudyConfig& c = r.config;
  std::vector<const Ladder*> ladders;
  for (const Ladder& l : c.ladders)
    if (isNumerical(l.factor) && !l.values.empty()) ladders.push_back(&l);
  if (ladders.empty()) {
    best.reason = "no numerical ladder";
    return best;
  }
  double baseSteps = 0;
  for (Drainage d : drainages) {
    const int b = baseRun(r, d);
    if (b < 0 || !r.runs.at(b).ok) {
      best.reason = "the base run is missing or failed";
      return best;
    }
    baseSteps += double(r.runs.at(b).particleSteps);
  }
  // per ladder: candidate rungs with their errors per drainage and step ratio
  struct Cand {
    double value;
    std::vector<double> err;
    double ratio;
  };
  std::vector<std::vector<Cand>> cands(ladders.size());
  const std::size_t nd = drainages.size();
  std::vector<double> baseSum(nd, 0.0);
  for (std::size_t i = 0; i < ladders.size(); ++i) {
    const Ladder& l = *ladders[i];
    for (Drainage d : drainages) {
      const Convergence* cv = findConvergence(r, l.factor, d, output);
      if (!cv || !cv->converged) {
        best.reason = std::string("the reference of the ") + factorKey(l.factor) + " ladder is not converged for " +
                      outputKey(output) + " (" + drainageKey(d) + ")";
        return best;
      }
    }
    for (double v : l.values) {
      Cand cand{v, std::vector<double>(nd, 0.0), 0.0};
      double steps = 0;
      bool ok = true;
      for (std::size_t k = 0; k < nd; ++k) {
        const Row* row = findRow(r, l.factor, v, drainages[k]);
        if (!row || !std::isfinite(row->errors[int(output)])) {
          ok = false;
          break;
        }
        cand.err[k] = row->errors[int(output)];
        steps += double(r.runs.at(row->run).particleSteps);
      }
      if (!ok) continue;
      cand.ratio = steps / baseSteps;
      if (v == c.base.value(l.factor))
        for (std::size_t k = 0; k < nd; ++k) baseSum[k] += cand.err[k];
      cands[i].push_back(cand);
    }
  }
  best.baseBound = *std::max_element(baseSum.begin(), baseSum.end());
  // exhaustive search (a few thousand combinations at most)
  std::vector<double> chosen(ladders.size());
  std::vector<double> sum(nd, 0.0);
  double bestCost = std::numeric_limits<double>::infinity(), bestBound = 0;
  std::vector<double> bestChoice;
  std::function<void(std::size_t, double)> walk = [&](std::size_t i, double cost) {
    if (i == ladders.size()) {
      const double bound = *std::max_element(sum.begin(), sum.end());
      if (!(bound < c.target)) return;
      if (cost < bestCost || (cost == bestCost && bound < bestBound)) {
        bestCost = cost;
        bestBound = bound;
        bestChoice = chosen;
      }
      return;
    }
    for (const Cand& cand : cands[i]) {
      chosen[i] = cand.value;
      // inertial number and density scaling both set the effective inertial number: change one at most
      bool changedI = false, changedS = false;
      for (std::size_t j = 0; j <= i; ++j) {
        if (ladders[j]->factor == Factor::InertialNumber && chosen[j] != c.base.inertialNumber) changedI = true;
        if (ladders[j]->factor == Factor::DensityScale && chosen[j] != c.base.densityScale) changedS = true;
      }
      if (changedI && changedS) continue;
      for (std::size_t k = 0; k < nd; ++k) sum[k] += cand.err[k];
      walk(i + 1, cost * cand.ratio);
      for (std::size_t k = 0; k < nd; ++k) sum[k] -= cand.err[k];
    }
  };
  walk(0, 1.0);
  if (bestChoice.empty()) {
    best.reason = "no combination of rungs has a summed error below the target";
    return best;
  }
  best.found = true;
  best.bound = bestBound;
  best.costRatio = bestCost;
  best.settings = c.base;
  for (std::size_t i = 0; i < ladders.size(); ++i) {
    best.rungs.emplace_back(ladders[i]->factor, bestChoice[i]);
    best.settings.set(ladders[i]->factor, bestChoice[i]);
  }
  if (best.settings.densityScale != c.base.densityScale) best.settings.strainRate = r.fixedRate;
  return best;
}

// ---- CSV and JSON --------------------------------------------------------------------------------------
std::string csvText(const StudyResult& r) {
  std::ostringstream o;
  o << "factor,value,drainage,run_id,reference,base,particles,inertial_number,time_step_factor,local_damping,"
       "restitution,density_scale,strain_rate_1_per_s,wall_s,cpu_s,steps,particle_steps,status";
  for (int k = 0; k < kOutputCount; ++k) o << ",err_" << outputKey(Output(k));
  o << ",G_sec_cycle1_Pa,G_sec_last_Pa,du_end_last_Pa,eps_v_end_last,Z_end_last,a_2D_end_last,max_inertial_number,"
       "max_energy_error,dt_over_rayleigh\n";
  auto val = [](double v) {
    if (!std::isfinite(v)) return std::string();
    char b[40];
    std::snprintf(b, sizeof b, "%.10g", v);
    return std::string(b);
  };
  auto last = [&](const std::vector<double>& x) { return x.empty() ? std::string() : val(x.back()); };
  for (const Row& row : r.rows) {
    const RunResult& run = r.runs.at(row.run);
    const Settings& s = run.settings;
    o << factorKey(row.factor) << ',' << val(row.value) << ',' << drainageKey(row.drainage) << ',' << row.run << ','
      << (row.reference ? 1 : 0) << ',' << (row.base ? 1 : 0) << ',' << s.particles << ',' << val(s.inertialNumber) << ','
      << val(s.timeStepFactor) << ',' << val(s.localDamping) << ',' << val(s.restitution) << ',' << val(s.densityScale)
      << ',' << val(s.strainRate) << ',' << val(run.wallSeconds) << ',' << val(run.cpuSeconds) << ',' << run.steps << ','
      << run.particleSteps << ',' << (run.ok ? "ok" : "failed");
    for (int k = 0; k < kOutputCount; ++k) o << ',' << val(row.errors[k]);
    const Metrics& m = run.metrics;
    o << ',' << (m.Gsec.empty() ? std::string() : val(m.Gsec.front())) << ',' << last(m.Gsec) << ','
      << (row.drainage == Drainage::Undrained ? last(m.du) : std::string()) << ','
      << (row.drainage == Drainage::Drained ? last(m.epsV) : std::string()) << ',' << last(m.Z) << ',' << last(m.a) << ','
      << val(run.maxInertialNumber) << ',' << val(run.maxEnergyError) << ',' << val(run.dtOverRayleigh) << '\n';
  }
  // runs of combined settings (not a rung of a ladder): errors against the extrapolated converged result
  for (const RunResult& run : r.runs) {
    bool inLadder = false;
    for (const Row& row : r.rows) inLadder = inLadder || row.run == run.id;
    if (inLadder) continue;
    const Settings& s = run.settings;
    o << "combination,," << drainageKey(run.drainage) << ',' << run.id << ",0,0," << s.particles << ','
      << val(s.inertialNumber) << ',' << val(s.timeStepFactor) << ',' << val(s.localDamping) << ',' << val(s.restitution)
      << ',' << val(s.densityScale) << ',' << val(s.strainRate) << ',' << val(run.wallSeconds) << ',' << val(run.cpuSeconds)
      << ',' << run.steps << ',' << run.particleSteps << ',' << (run.ok ? "ok" : "failed");
    for (int k = 0; k < kOutputCount; ++k)
      o << ',' << (appliesTo(Output(k), run.drainage) && run.ok
                       ? val(relativeError(run.metrics.of(Output(k)), extrapolatedReference(r, Output(k), run.drainage)))
                       : std::string());
    const Metrics& m = run.metrics;
    o << ',' << (m.Gsec.empty() ? std::string() : val(m.Gsec.front())) << ',' << last(m.Gsec) << ','
      << (run.drainage == Drainage::Undrained ? last(m.du) : std::string()) << ','
      << (run.drainage == Drainage::Drained ? last(m.epsV) : std::string()) << ',' << last(m.Z) << ',' << last(m.a) << ','
      << val(run.maxInertialNumber) << ',' << val(run.maxEnergyError) << ',' << val(run.dtOverRayleigh) << '\n';
  }
  return o.str();
}

namespace {
json settingsJson(const Settings& s) {
  return {{"inertial_number", s.inertialNumber}, {"time_step_factor", s.timeStepFactor}, {"local_damping", s.localDamping},
          {"restitution", s.restitution},        {"density_scale", s.densityScale},      {"particles", s.particles},
          {"strain_rate", s.strainRate}};
}
Settings settingsFrom(const json& j) {
  Settings s;
  s.inertialNumber = j.at("inertial_number");
  s.timeStepFactor = j.at("time_step_factor");
  s.localDamping = j.at("local_damping");
  s.restitution = j.at("restitution");
  s.densityScale = j.at("density_scale");
  s.particles = j.at("particles");
  s.strainRate = j.at("strain_rate");
  return s;
}
Factor factorFrom(const std::string& k) {
  for (Factor f : kFactors)
    if (k == factorKey(f)) return f;
  throw InputError("unknown factor '" + k + "'");
}
}  // namespace

json resultJson(const StudyResult& r) {
  json j;
  const StudyConfig& c = r.config;
  j["config"] = {{"base", settingsJson(c.base)},
                 {"cycles", c.cycles},
                 {"amplitude", c.amplitude},
                 {"pressure", c.pressure},
                 {"samples_per_cycle", c.samplesPerCycle},
                 {"convergence_tolerance", c.convergenceTolerance},
                 {"target", c.target},
                 {"seed", c.seed},
                 {"jobs", c.jobs},
                 {"quick", c.quick}};
  for (const Ladder& l : c.ladders) j["config"]["ladders"].push_back({{"factor", factorKey(l.factor)}, {"values", l.values}});
  j["specimens"] = json::array();
  for (const SpecimenInfo& s : r.specimens)
    j["specimens"].push_back({{"particles", s.particles}, {"checkpoint", s.checkpoint}, {"p", s.p}, {"void_ratio", s.voidRatio},
                              {"Z", s.Z}, {"a_2D", s.a2D}, {"mean_diameter", s.meanDiameter},
                              {"prepare_seconds", s.prepareSeconds}});
  j["runs"] = json::array();
  for (const RunResult& run : r.runs) {
    json m;
    for (int k = 0; k < kOutputCount; ++k) m[outputKey(Output(k))] = run.metrics.of(Output(k));
    j["runs"].push_back({{"id", run.id},
                         {"settings", settingsJson(run.settings)},
                         {"drainage", drainageKey(run.drainage)},
                         {"ok", run.ok},
                         {"error", run.error},
                         {"metrics", m},
                         {"wall_s", run.wallSeconds},
                         {"cpu_s", run.cpuSeconds},
                         {"steps", run.steps},
                         {"particle_steps", run.particleSteps},
                         {"max_inertial_number", run.maxInertialNumber},
                         {"max_energy_error", run.maxEnergyError},
                         {"dt_over_rayleigh", run.dtOverRayleigh}});
  }
  j["wall_s"] = r.wallSeconds;
  j["cpu_s"] = r.cpuSeconds;
  j["machine"] = r.machine;
  j["fixed_rate"] = r.fixedRate;
  j["command"] = r.command;
  return j;
}

StudyResult resultFromJson(const json& j) {
  StudyResult r;
  const json& c = j.at("config");
  r.config.base = settingsFrom(c.at("base"));
  r.config.cycles = c.at("cycles");
  r.config.amplitude = c.at("amplitude");
  r.config.pressure = c.at("pressure");
  r.config.samplesPerCycle = c.at("samples_per_cycle");
  r.config.convergenceTolerance = c.at("convergence_tolerance");
  r.config.target = c.at("target");
  r.config.seed = c.at("seed");
  r.config.jobs = c.at("jobs");
  r.config.quick = c.at("quick");
  for (const json& l : c.at("ladders")) r.config.ladders.push_back({factorFrom(l.at("factor")), l.at("values").get<std::vector<double>>()});
  for (const json& s : j.at("specimens"))
    r.specimens.push_back({s.at("particles"), s.at("checkpoint"), s.at("p"), s.at("void_ratio"), s.at("Z"), s.at("a_2D"),
                           s.at("mean_diameter"), s.at("prepare_seconds")});
  for (const json& x : j.at("runs")) {
    RunResult run;
    run.id = x.at("id");
    run.settings = settingsFrom(x.at("settings"));
    run.drainage = x.at("drainage") == "undrained" ? Drainage::Undrained : Drainage::Drained;
    run.ok = x.at("ok");
    run.error = x.at("error");
    for (int k = 0; k < kOutputCount; ++k)
      run.metrics.of(Output(k)) = x.at("metrics").at(outputKey(Output(k))).get<std::vector<double>>();
    run.wallSeconds = x.at("wall_s");
    run.cpuSeconds = x.at("cpu_s");
    run.steps = x.at("steps");
    run.particleSteps = x.at("particle_steps");
    run.maxInertialNumber = x.at("max_inertial_number");
    run.maxEnergyError = x.at("max_energy_error");
    run.dtOverRayleigh = x.at("dt_over_rayleigh");
    r.runs.push_back(run);
  }
  r.wallSeconds = j.at("wall_s");
  r.cpuSeconds = j.at("cpu_s");
  r.machine = j.at("machine");
  r.fixedRate = j.at("fixed_rate");
  r.command = j.value("command", std::string());
  evaluate(r, [&](Factor f, double v, Drainage d) { return findRun(r, f, v, d); });
  return r;
}

int findRun(const StudyResult& r, Factor f, double v, Drainage d) {
  const Settings want = rungSettings(r.config, f, v, r.fixedRate);
  for (const RunResult& run : r.runs)
    if (run.drainage == d && sameSettings(run.settings, want)) return run.id;
  throw Error(std::string("no run for ") + factorKey(f) + " = " + num(v) + " (" + drainageKey(d) + ")");
}

Settings rungSettings(const StudyConfig& c, Factor f, double v, double fixedRate) {
  Settings s = c.base;
  s.set(f, v);
  if (f == Factor::DensityScale && v != c.base.densityScale) s.strainRate = fixedRate;
  return s;
}

// ---- plots ---------------------------------------------------------------------------------------------
std::vector<PlotSpec> plots(const StudyResult& r) {
  std::vector<PlotSpec> out;
  for (int o = 0; o < kOutputCount; ++o) {
    for (Drainage d : kDrainages) {
      if (!appliesTo(Output(o), d)) continue;
      PlotSpec p;
      p.file = std::string(outputKey(Output(o))) + "-" + drainageKey(d) + ".png";
      p.title = std::string("Error of ") + outputTitle(Output(o)) + " against wall time (" + drainageKey(d) + ", " +
                std::to_string(r.config.cycles) + " cycle" + (r.config.cycles > 1 ? "s" : "") + ")";
      p.xLabel = "wall time of the run [s]";
      p.yLabel = "relative error against the ladder's reference [-]";
      std::vector<double> cost, err;
      double xmin = std::numeric_limits<double>::infinity(), xmax = 0;
      for (const Ladder& l : r.config.ladders) {
        if (!isNumerical(l.factor)) continue;
        PlotSeries s;
        s.name = factorKey(l.factor);
        for (const Row& row : r.rows) {
          if (row.factor != l.factor || row.drainage != d || row.reference) continue;
          const double e = row.errors[o], w = r.runs.at(row.run).wallSeconds;
          if (!(e > 0) || !std::isfinite(e) || !(w > 0)) continue;  // log axes
          s.x.push_back(w);
          s.y.push_back(e);
          cost.push_back(w);
          err.push_back(e);
          xmin = std::min(xmin, w);
          xmax = std::max(xmax, w);
        }
        if (!s.x.empty()) p.series.push_back(s);
      }
      if (p.series.empty()) continue;
      PlotSeries front{"Pareto front", {}, {}, false};
      for (std::size_t k : paretoFront(cost, err)) {
        front.x.push_back(cost[k]);
        front.y.push_back(err[k]);
      }
      p.series.push_back({fmt("%g %% target", 100 * r.config.target), {xmin, xmax}, {r.config.target, r.config.target}, false});
      p.series.push_back(front);
      out.push_back(p);
    }
  }
  // size effect: deviation from the largest specimen against the particle count
  for (Drainage d : kDrainages) {
    PlotSpec p;
    p.file = std::string("size-effect-") + drainageKey(d) + ".png";
    p.title = std::string("Size effect: deviation from the largest specimen (") + drainageKey(d) + ")";
    p.xLabel = "particle count";
    p.yLabel = "relative deviation from the largest count [-]";
    for (Output o : {Output::Gsec, Output::PReversal, Output::QReversal, Output::Du, Output::EpsV}) {
      if (!appliesTo(o, d)) continue;
      PlotSeries s;
      s.name = outputKey(o);
      for (const Row& row : r.rows) {
        if (row.factor != Factor::ParticleCount || row.drainage != d || row.reference) continue;
        if (!(row.errors[int(o)] > 0) || !std::isfinite(row.errors[int(o)])) continue;
        s.x.push_back(row.value);
        s.y.push_back(row.errors[int(o)]);
      }
      if (!s.x.empty()) p.series.push_back(s);
    }
    if (!p.series.empty()) out.push_back(p);
  }
  return out;
}

// ---- report --------------------------------------------------------------------------------------------

std::string reportMarkdown(const StudyResult& r, const std::string& imageDir, const std::vector<std::string>& images,
                           const std::string& command) {
  const StudyConfig& c = r.config;
  std::ostringstream o;
  o << "# Accuracy against cost of the cyclic test (issue 7, part 1)\n\n";
  const std::string measuredBy = r.command.empty() ? command : r.command;
  o << "Generated by `" << measuredBy << "` (" << (c.quick ? "quick CI ladder" : "the full study")
    << "); every number below is measured by that run — regenerate with the same command.";
  if (measuredBy != command) o << " Tables and plots re-written from its `results.json` by `" << command << "`.";
  o << "\n\n";
  o << "Whole study: **" << secs(r.wallSeconds) << " wall, " << secs(r.cpuSeconds) << " CPU** (" << c.jobs
    << " job" << (c.jobs > 1 ? "s" : "") << ", one thread per run). Machine: " << r.machine << ".\n\n";

  // setup
  o << "## Set-up\n\n";
  o << "- Specimens: the paper's glass beads (G = 28.688 GPa, ν = 0.22, ρ = 2570 kg/m³, μ = 0.235, seven sizes "
       "0.8–1.4 mm), a random gas (solid fraction 0.3, seed "
    << c.seed
    << ") compressed to 50 kPa with compression friction μ_c = 0.02, then consolidated isotropically to p′ = "
    << num(c.pressure / 1e3)
    << " kPa (preparation numerics: time_step_factor 0.3, local damping 0.1, density scale 100, max inertial number "
       "1e-2; not under study). One checkpoint per particle count; every run branches from it.\n";
  o << "\n| particles | p′ [kPa] | e | Z | a_2D | preparation wall |\n|---|---|---|---|---|---|\n";
  for (const SpecimenInfo& s : r.specimens)
    o << "| " << s.particles << " | " << fmt("%.1f", s.p / 1e3) << " | " << fmt("%.3f", s.voidRatio) << " | "
      << fmt("%.2f", s.Z) << " | " << fmt("%.3f", s.a2D) << " | " << secs(s.prepareSeconds) << " |\n";
  o << "\n- Test: the first " << c.cycles << " strain-controlled cycle" << (c.cycles > 1 ? "s" : "") << " of ε_a = ±"
    << num(100 * c.amplitude) << " %, undrained (constant volume) and drained (lateral stresses held), "
    << c.samplesPerCycle << " samples per cycle.\n";
  o << "- Base setting (the paper's cyclic numerics): inertial number " << num(c.base.inertialNumber)
    << ", time_step_factor " << num(c.base.timeStepFactor) << ", local damping " << num(c.base.localDamping)
    << ", restitution " << num(c.base.restitution) << " (no contact damping), density scale " << num(c.base.densityScale)
    << ", " << c.base.particles << " particles";
  if (!c.quick && c.base.particles < 4000) {
    // what the same ladders would cost at the paper's size, from this run's own CPU times (cost ~ particles)
    double cpuBase = 0;
    for (const RunResult& run : r.runs)
      if (run.settings.particles == c.base.particles) cpuBase += run.cpuSeconds;
    o << " (**smaller than the paper's 4000 spheres, to fit the study into 25 minutes on one core**: the "
         "numerical ladders took "
      << secs(cpuBase) << " of CPU here and would take about " << secs(cpuBase * 4000.0 / c.base.particles)
      << " at 4000 spheres, before the specimens and the particle-count ladder; that ladder shows what the size "
         "changes)";
  }
  o << ".\n- Ladders, one factor at a time from the base (coarsest first; the last rung is the reference):\n";
  for (const Ladder& l : c.ladders) {
    o << "  - " << factorTitle(l.factor) << ": ";
    for (std::size_t k = 0; k < l.values.size(); ++k) o << (k ? ", " : "") << num(l.values[k]);
    o << "\n";
  }
  o << "- Density scaling keeps the physical strain rate of the base (that of I = " << num(c.base.inertialNumber)
    << " without scaling): mass × s makes the time step √s larger and the inertial number √s larger. (At a fixed "
       "inertial number, density scaling changes nothing but the units of time: the same steps, the same results.)\n";
  o << "- Wall time is the cyclic stage of one run on one thread (loading the checkpoint excluded); CPU time of that "
       "thread and particle-steps are in the CSV. The time step follows the contact stiffness "
       "(guards.adaptive_time_step): the dt actually used is in the CSV (dt_over_rayleigh).\n\n";

  o << "## Error measure\n\n";
  o << "For each output, a list of values over the cycles x_k, a run's error against its ladder's reference is\n"
       "err = max_k |x_k − x_ref,k| / max_k |x_ref,k|. Outputs: G_sec of every cycle; p′ and q at both reversals "
       "(ε_a = +A, −A) of every cycle; Δu at the end of every cycle (undrained); ε_v at the end of every cycle "
       "(drained); Z and a_2D (Rothenburg–Bathurst, the paper's measure) at the end of every cycle. "
       "The error of a rung is the error due to that factor with all others at the base.\n\n";

  // convergence
  o << "## Is the reference converged?\n\n";
  o << "A ladder's reference (its finest rung) is called converged for an output when the two finest rungs agree "
       "within **"
    << pct(c.convergenceTolerance)
    << "** (same error measure); ✓ marks those. Where it is not, no rung of that ladder is certified below the "
       "target for that output. Three ladders end at the exact limit of their factor (local damping 0, restitution 1 "
       "= no contact damping, density scale 1): their reference has no error in that factor by construction, and the "
       "number shown is how far the next rung already moves the result (sensitivity, not convergence).\n\n";
  o << "| factor | drainage | finest vs second finest |";
  for (int k = 0; k < kOutputCount; ++k) o << " " << outputKey(Output(k)) << " |";
  o << "\n|---|---|---|";
  for (int k = 0; k < kOutputCount; ++k) o << "---|";
  o << "\n";
  bool anyNotConverged = false;
  for (const Ladder& l : c.ladders) {
    for (Drainage d : kDrainages) {
      const Convergence* any = nullptr;
      std::ostringstream cells;
      for (int k = 0; k < kOutputCount; ++k) {
        const Convergence* cv = findConvergence(r, l.factor, d, Output(k));
        if (!cv) {
          cells << " — |";
          continue;
        }
        any = cv;
        const bool numerical = isNumerical(l.factor);
        cells << " " << pct(cv->disagreement)
              << (!numerical        ? " (size effect)"
                  : cv->exactLimit  ? " (exact limit)"
                  : cv->converged   ? " ✓"
                                    : " **NOT converged**")
              << " |";
        if (numerical && !cv->converged && (Output(k) == Output::Gsec || Output(k) == Output::Du)) anyNotConverged = true;
      }
      if (!any) continue;
      o << "| " << factorKey(l.factor) << " | " << drainageKey(d) << " | " << num(any->finest) << " vs "
        << num(any->second) << " |" << cells.str() << "\n";
    }
  }
  o << "\n";
  if (anyNotConverged)
    o << "**Warning: at least one reference is NOT converged for G_sec or Δu** (marked above): the errors of that "
         "ladder are measured against a reference that itself moves by more than "
      << pct(c.convergenceTolerance) << "; extend the ladder before trusting them.\n\n";

  // headline
  o << "## Cheapest settings below " << pct(c.target) << "\n\n";
  o << "To first order the errors of the factors add: the error of a whole setting is bounded by the sum of its "
       "rungs' errors, each against its own ladder's reference (a factor left at the base contributes the base "
       "rung's error). The cheapest combination of rungs whose summed error is below the target is searched over "
       "all numerical ladders (cost: the base run's particle-steps times each rung's step ratio; inertial number and "
       "density scaling both set the effective inertial number, so at most one of them leaves the base), and then "
       "**run once** to measure its actual error against the additive estimate of the result converged in every "
       "factor, x_conv = x_base − Σ_f (x_base − x_ref,f).\n\n";
  auto settingsText = [&](const Settings& s) {
    std::ostringstream t;
    t << "inertial number " << num(s.inertialNumber) << ", time_step_factor " << num(s.timeStepFactor)
      << ", local damping " << num(s.localDamping) << ", restitution " << num(s.restitution) << ", density scale "
      << num(s.densityScale);
    if (s.strainRate > 0) t << " at the base's physical strain rate (" << fmt("%.3g", s.strainRate) << " /s)";
    return t.str();
  };
  auto measured = [&](const Settings& s, Output out, const std::vector<Drainage>& ds, double* wall) {
    std::ostringstream t;
    *wall = 0;
    bool first = true;
    for (Drainage d : ds) {
      const int id = runWithSettings(r, s, d);
      const std::vector<double> conv = extrapolatedReference(r, out, d);
      t << (first ? "" : ", ");
      first = false;
      if (id < 0 || !r.runs.at(id).ok || conv.empty()) {
        t << "not run (" << drainageKey(d) << ")";
        continue;
      }
      *wall += r.runs.at(id).wallSeconds;
      t << pct(relativeError(r.runs.at(id).metrics.of(out), conv)) << " " << drainageKey(d);
    }
    return t.str();
  };
  auto headline = [&](Output out, const std::vector<Drainage>& ds, const std::string& label) {
    const Combination cb = cheapestCombination(r, out, ds);
    o << "- **Cheapest setting with < " << pct(c.target) << " error on " << label << "**: ";
    double baseWall = 0;
    const std::string baseMeasured = measured(c.base, out, ds, &baseWall);
    if (!cb.found) {
      o << "none found — " << cb.reason << ".\n";
    } else {
      double wall = 0;
      const std::string m = measured(cb.settings, out, ds, &wall);
      o << settingsText(cb.settings) << ". Summed error bound " << pct(cb.bound) << "; " << fmt("%.3g", cb.costRatio)
        << " × the base's particle-steps. **Measured error " << m << "**; " << secs(wall) << " wall for " << c.cycles
        << " cycle" << (c.cycles > 1 ? "s" : "") << (ds.size() > 1 ? " of both tests" : "") << " against "
        << secs(baseWall) << " for the base.\n";
    }
    o << "  The base setting (" << settingsText(c.base) << ") has a summed bound of "
      << (cb.found || cb.baseBound > 0 ? pct(cb.baseBound) : std::string("n/a")) << " and a measured error of "
      << baseMeasured << ".\n";
  };
  headline(Output::Gsec, {Drainage::Undrained, Drainage::Drained}, "G_sec (undrained and drained)");
  headline(Output::Du, {Drainage::Undrained}, "Δu (undrained)");
  o << "\n### One factor at a time\n\n";
  o << "The cheapest rung of each ladder whose own error is below the target (fewest particle-steps; ✗: none; "
       "“not converged”: reference not converged); the other factors at the base:\n\n";
  o << "| factor | G_sec (both tests) | Δu |\n|---|---|---|\n";
  for (const Ladder& l : c.ladders) {
    if (!isNumerical(l.factor)) continue;
    StudyResult one = r;
    one.config.ladders = {l};
    auto cell = [&](Output out, const std::vector<Drainage>& ds) -> std::string {
      bool conv = true;
      for (Drainage d : ds) {
        const Convergence* cv = findConvergence(r, l.factor, d, out);
        conv = conv && cv && cv->converged;
      }
      if (!conv) return "not converged";
      const Cheapest ch = cheapestBelow(one, out, ds);
      if (!ch.found) return "✗";
      return num(ch.value) + " (" + pct(ch.worstError) + ", " + secs(ch.wallSeconds) + ")";
    };
    o << "| " << factorKey(l.factor) << " | " << cell(Output::Gsec, {Drainage::Undrained, Drainage::Drained}) << " | "
      << cell(Output::Du, {Drainage::Undrained}) << " |\n";
  }
  o << "\n";

  // per-factor tables
  o << "## All runs\n\n";
  for (const Ladder& l : c.ladders) {
    o << "### " << factorTitle(l.factor) << "\n\n";
    if (!isNumerical(l.factor))
      o << "Different specimens (same preparation, different particle count): the deviation from the largest "
           "specimen is a **size effect** (and specimen-to-specimen scatter), not a numerical error.\n\n";
    o << "| value | drainage | wall | CPU | particle-steps | dt/Rayleigh | max I |";
    for (int k = 0; k < kOutputCount; ++k) o << " err " << outputKey(Output(k)) << " |";
    o << " G_sec cycle 1 [MPa] | Δu or ε_v at end |\n|---|---|---|---|---|---|---|";
    for (int k = 0; k < kOutputCount; ++k) o << "---|";
    o << "---|---|\n";
    for (const Row& row : r.rows) {
      if (row.factor != l.factor) continue;
      const RunResult& run = r.runs.at(row.run);
      o << "| " << num(row.value) << (row.reference ? " (ref)" : "") << (row.base ? " (base)" : "") << " | "
        << drainageKey(row.drainage) << " | " << (run.ok ? secs(run.wallSeconds) : "failed: " + run.error.substr(0, 60))
        << " | " << secs(run.cpuSeconds) << " | " << fmt("%.3g", double(run.particleSteps)) << " | "
        << fmt("%.3f", run.dtOverRayleigh) << " | " << fmt("%.2g", run.maxInertialNumber) << " |";
      for (int k = 0; k < kOutputCount; ++k) o << " " << (row.reference ? std::string("ref") : pct(row.errors[k])) << " |";
      const Metrics& m = run.metrics;
      o << " " << (m.Gsec.empty() ? std::string("—") : fmt("%.1f", m.Gsec.front() / 1e6)) << " | ";
      if (row.drainage == Drainage::Undrained)
        o << (m.du.empty() ? std::string("—") : fmt("%.2f kPa", m.du.back() / 1e3));
      else
        o << (m.epsV.empty() ? std::string("—") : fmt("%.3e", m.epsV.back()));
      o << " |\n";
    }
    o << "\n";
  }

  {
    std::ostringstream t;
    int n = 0;
    for (const RunResult& run : r.runs) {
      bool inLadder = false;
      for (const Row& row : r.rows) inLadder = inLadder || row.run == run.id;
      if (inLadder) continue;
      ++n;
      const Settings& s = run.settings;
      t << "| " << num(s.inertialNumber) << ", " << num(s.timeStepFactor) << ", " << num(s.localDamping) << ", "
        << num(s.restitution) << ", " << num(s.densityScale) << " | " << drainageKey(run.drainage) << " | "
        << (run.ok ? secs(run.wallSeconds) : "failed: " + run.error.substr(0, 60)) << " | "
        << fmt("%.3g", double(run.particleSteps)) << " |";
      for (int k = 0; k < kOutputCount; ++k)
        t << " "
          << (appliesTo(Output(k), run.drainage) && run.ok
                  ? pct(relativeError(run.metrics.of(Output(k)), extrapolatedReference(r, Output(k), run.drainage)))
                  : std::string("n/a"))
          << " |";
      t << "\n";
    }
    // the base against the same extrapolated reference, for comparison
    for (Drainage d : kDrainages) {
      const int b = baseRun(r, d);
      if (b < 0 || !r.runs.at(b).ok) continue;
      t << "| base | " << drainageKey(d) << " | " << secs(r.runs.at(b).wallSeconds) << " | "
        << fmt("%.3g", double(r.runs.at(b).particleSteps)) << " |";
      for (int k = 0; k < kOutputCount; ++k)
        t << " "
          << (appliesTo(Output(k), d) ? pct(relativeError(r.runs.at(b).metrics.of(Output(k)), extrapolatedReference(r, Output(k), d)))
                                      : std::string("n/a"))
          << " |";
      t << "\n";
    }
    if (n > 0) {
      o << "### Combined settings, checked\n\n";
      o << "Errors against the extrapolated converged result x_conv (see above).\n\n";
      o << "| I, time_step_factor, α, e, density scale | drainage | wall | particle-steps |";
      for (int k = 0; k < kOutputCount; ++k) o << " err " << outputKey(Output(k)) << " |";
      o << "\n|---|---|---|---|";
      for (int k = 0; k < kOutputCount; ++k) o << "---|";
      o << "\n" << t.str() << "\n";
    }
  }

  o << "## Plots\n\n";
  o << "The table of every run (one row per rung and test: factor, value, wall and CPU seconds, steps, "
       "particle-steps, every error, the raw values) is [`"
    << imageDir << "/accuracy.csv`](" << imageDir << "/accuracy.csv).\n\n";
  if (images.empty()) {
    o << "No plots were drawn by this run (the command was built without the Qt chart library, or the study was run "
         "in-process by a test); the CSV holds every point.\n\n";
  } else {
    o << "Log–log, error against wall time, one point per run (references, with error 0 by definition, are not "
         "drawn; neither are errors that are exactly 0). The Pareto front is the line through the runs no other run "
         "beats in both cost and error (over all numerical ladders: each point's error is that of its own factor). "
         "The size-effect plots show the deviation from the largest specimen against the particle count.\n\n";
    for (const std::string& f : images) o << "![" << f << "](" << imageDir << "/" << f << ")\n\n";
  }

  o << "## Caveats\n\n";
  o << "- One factor at a time: each rung's error is measured with the other factors at the base; the reference of "
       "one ladder carries the base's error in the other factors. The summed bound and x_conv assume that the "
       "factors' effects add (first order); the checked combined settings test that assumption (their measured error "
       "should stay below their bound). Errors of opposite sign can cancel, so the measured error of a setting can be "
       "far below its bound.\n";
  o << "- Z and a_2D change little over " << c.cycles
    << " cycles and the error of a small anisotropy is large relative to its value; their references are the least "
       "likely to be converged.\n";
  o << "- Wall times depend on the machine's load (stated above); the CPU column is the run's own thread and is "
       "less sensitive to other processes.\n";
  return o.str();
}

// ---- running -------------------------------------------------------------------------------------------
namespace {

// Collects the per-cycle outputs from the runner's samples and cycle records.
struct Collector final : RunObserver {
  Metrics* m;
  double maxI = 0, maxErr = 0;
  bool have = false;
  Sample top, bottom;  // the samples at the largest and smallest eps_a of the current cycle
  explicit Collector(Metrics* out) : m(out) {}
  void onSample(const Sample& s) override {
    maxI = std::max(maxI, s.inertialNumber);
    maxErr = std::max(maxErr, s.energyError);
    if (s.cycle <= 0) return;
    if (!have) {
      top = bottom = s;
      have = true;
    }
    if (s.epsA > top.epsA) top = s;
    if (s.epsA < bottom.epsA) bottom = s;
  }
  void onCycle(const CycleRecord& c) override {
    m->Gsec.push_back(c.Gsec);
    m->pReversal.push_back(top.p);
    m->pReversal.push_back(bottom.p);
    m->qReversal.push_back(top.q);
    m->qReversal.push_back(bottom.q);
    m->du.push_back(c.duEnd);
    m->epsV.push_back(c.end.epsV);
    m->Z.push_back(c.end.Z);
    m->a.push_back(c.end.a2D);
    have = false;
  }
};

json runScene(const StudyConfig& c, const Settings& s, Drainage d, const std::string& checkpoint) {
  json stage = {{"type", "cyclic"},
                {"name", "cycles"},
                {"drainage", drainageKey(d)},
                {"amplitude", c.amplitude},
                {"cycles", c.cycles},
                {"inertial_number", s.inertialNumber},
                {"strain_rate", s.strainRate},
                {"samples_per_cycle", c.samplesPerCycle}};
  return {{"name", "accuracy study run"},
          {"specimen", {{"source", "checkpoint"}, {"path", checkpoint}}},
          {"numerics",
           {{"time_step_factor", s.timeStepFactor},
            {"local_damping", s.localDamping},
            {"restitution", s.restitution},
            {"density_scale", s.densityScale},
            {"threads", 1}}},
          {"stages", json::array({stage})},
          {"output", {{"sample_interval", 100000}, {"checkpoint_at_stage_end", false}}}};
}

RunResult runOne(const StudyConfig& c, const Settings& s, Drainage d, const std::string& checkpoint) {
  RunResult res;
  res.settings = s;
  res.drainage = d;
  try {
    Runner r(parseScene(runScene(c, s, d, checkpoint), "accuracy-run.json"));
    Collector col(&res.metrics);
    r.addObserver(&col);
    const long step0 = r.simulation().stepCount();
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = threadCpuSeconds();
    while (r.advance(10000)) {
    }
    res.cpuSeconds = threadCpuSeconds() - c0;
    res.wallSeconds = since(t0);
    res.steps = r.simulation().stepCount() - step0;
    res.particleSteps = res.steps * static_cast<long>(r.simulation().particles().size());
    res.maxInertialNumber = col.maxI;
    res.maxEnergyError = col.maxErr;
    res.dtOverRayleigh = r.simulation().timeStep() / r.simulation().rayleighStep();
    res.ok = static_cast<int>(res.metrics.Gsec.size()) == c.cycles;
    if (!res.ok) res.error = "finished with " + std::to_string(res.metrics.Gsec.size()) + " cycles";
  } catch (const std::exception& e) {
    res.ok = false;
    res.error = e.what();
    res.metrics = Metrics{};
  }
  return res;
}

struct Prepared {
  SpecimenInfo info;
  double baseRate = 0;  // strain rate of the base inertial number without density scaling [1/s]
};

Prepared prepare(const StudyConfig& c, int particles, const std::string& dir) {
  json scene = {
      {"name", "accuracy study specimen"},
      {"specimen", {{"source", "gas"}, {"count", particles}, {"solid_fraction", 0.3}, {"seed", c.seed}}},
      {"numerics", {{"time_step_factor", 0.3}, {"local_damping", 0.1}, {"density_scale", 100}, {"threads", 1}}},
      {"servo", {{"max_strain_rate", 10}, {"max_inertial_number", 1e-2}, {"unbalanced_tolerance", 5e-3}}},
      {"stages", json::array({{{"type", "isotropic_compression"}, {"name", "deposition"}, {"pressure", 50e3},
                               {"friction", 0.02}, {"friction_after", 0.235}},
                              {{"type", "isotropic_compression"}, {"name", "consolidation"}, {"pressure", c.pressure}}})},
      {"output", {{"directory", dir}, {"sample_interval", 100000}, {"checkpoint_at_stage_end", true}}}};
  const auto t0 = std::chrono::steady_clock::now();
  Runner r(parseScene(scene, "accuracy-specimen.json"));
  while (r.advance(10000)) {
  }
  Prepared p;
  p.info.prepareSeconds = since(t0);
  p.info.particles = particles;
  p.info.checkpoint = r.summaries().back().checkpoint;
  const Sample& e = r.summaries().back().end;
  p.info.p = e.p;
  p.info.voidRatio = e.voidRatio;
  p.info.Z = e.Z;
  p.info.a2D = e.a2D;
  p.info.meanDiameter = meanDiameter(r.simulation().particles());
  // the runner's own formula (Runner::axialRate) at density scale 1
  const double rho = r.scene().material.density;
  p.baseRate = c.base.inertialNumber / (p.info.meanDiameter * std::sqrt(rho / std::max(stressMeasures(r.simulation().contactStress()).p, 1.0)));
  return p;
}

// Runs tasks 0..n-1 on `jobs` threads (each task is independent).
void parallelFor(int n, int jobs, const std::function<void(int)>& task) {
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int k; (k = next.fetch_add(1)) < n;) task(k);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(jobs, n); ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

std::string machineText() {
  std::ostringstream o;
  o << std::thread::hardware_concurrency() << " cores";
  std::ifstream la("/proc/loadavg");
  double l1 = 0, l5 = 0, l15 = 0;
  if (la >> l1 >> l5 >> l15) o << ", load average " << l1 << " / " << l5 << " / " << l15 << " (1 / 5 / 15 min, at the end)";
  return o.str();
}

}  // namespace

StudyResult runStudy(const StudyConfig& config, const std::string& workDir,
                     const std::function<void(const std::string&)>& log) {
  StudyResult res;
  res.config = config;
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();
  std::mutex logMutex;
  auto say = [&](const std::string& m) {
    std::lock_guard<std::mutex> lock(logMutex);
    if (log) log(m);
  };

  // 1. specimens: the base count and every count of the particle ladder
  std::set<int> counts = {config.base.particles};
  for (const Ladder& l : config.ladders)
    if (l.factor == Factor::ParticleCount)
      for (double v : l.values) counts.insert(static_cast<int>(std::lround(v)));
  const std::vector<int> countList(counts.begin(), counts.end());
  std::vector<Prepared> prepared(countList.size());
  std::vector<std::string> prepErrors(countList.size());
  // largest first: the longest task starts first when jobs > 1
  parallelFor(static_cast<int>(countList.size()), config.jobs, [&](int k) {
    const int idx = static_cast<int>(countList.size()) - 1 - k;
    const int n = countList[idx];
    say("preparing the " + std::to_string(n) + "-sphere specimen ...");
    try {
      prepared[idx] = prepare(config, n, (fs::path(workDir) / "specimens" / std::to_string(n)).string());
      say("  " + std::to_string(n) + " spheres ready: p' " + fmt("%.1f kPa", prepared[idx].info.p / 1e3) + ", e " +
          fmt("%.3f", prepared[idx].info.voidRatio) + " (" + secs(prepared[idx].info.prepareSeconds) + ")");
    } catch (const std::exception& e) {
      prepErrors[idx] = e.what();
    }
  });
  for (std::size_t k = 0; k < countList.size(); ++k) {
    if (!prepErrors[k].empty())
      throw Error("preparing the " + std::to_string(countList[k]) + "-sphere specimen failed: " + prepErrors[k]);
    res.specimens.push_back(prepared[k].info);
  }
  auto specimenOf = [&](int n) -> const Prepared& {
    for (std::size_t k = 0; k < countList.size(); ++k)
      if (countList[k] == n) return prepared[k];
    throw Error("no specimen of " + std::to_string(n) + " spheres");
  };
  // the fixed physical rate of the density ladder is the base specimen's
  const double fixedRate = specimenOf(config.base.particles).baseRate;
  res.fixedRate = fixedRate;

  // 2. the distinct runs
  struct Task {
    Settings s;
    Drainage d;
  };
  std::vector<Task> tasks;
  auto indexOf = [&](const Settings& s, Drainage d) {
    for (std::size_t k = 0; k < tasks.size(); ++k)
      if (tasks[k].d == d && sameSettings(tasks[k].s, s)) return static_cast<int>(k);
    return -1;
  };
  for (Drainage d : kDrainages)
    for (const Ladder& l : config.ladders)
      for (double v : l.values) {
        const Settings s = rungSettings(config, l.factor, v, fixedRate);
        if (indexOf(s, d) < 0) tasks.push_back({s, d});
      }
  // expected cost ~ particles x cycles / (rate x dt): longest first so that parallel jobs finish together
  auto cost = [&](const Task& t) {
    const double sd = std::sqrt(t.s.densityScale);
    // dt ~ time_step_factor sqrt(density scale); physical rate ~ I / sqrt(density scale) or the fixed rate
    const double rate = t.s.strainRate > 0 ? t.s.strainRate / fixedRate * config.base.inertialNumber : t.s.inertialNumber / sd;
    return t.s.particles / (rate * t.s.timeStepFactor * sd);
  };
  std::vector<int> order(tasks.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return cost(tasks[a]) > cost(tasks[b]); });
  res.runs.resize(tasks.size());
  std::atomic<int> done{0};
  parallelFor(static_cast<int>(tasks.size()), config.jobs, [&](int k) {
    const int idx = order[k];
    const Task& t = tasks[idx];
    RunResult rr = runOne(config, t.s, t.d, specimenOf(t.s.particles).info.checkpoint);
    rr.id = idx;
    const int n = ++done;
    std::ostringstream m;
    m << "  [" << n << "/" << tasks.size() << "] " << drainageKey(t.d) << " N=" << t.s.particles << " I=" << num(t.s.inertialNumber)
      << " tsf=" << num(t.s.timeStepFactor) << " alpha=" << num(t.s.localDamping) << " e=" << num(t.s.restitution)
      << " ds=" << num(t.s.densityScale) << (t.s.strainRate > 0 ? " rate=" + num(t.s.strainRate) : std::string()) << ": "
      << (rr.ok ? secs(rr.wallSeconds) + ", G_sec(1) " + fmt("%.2f MPa", rr.metrics.Gsec.front() / 1e6) : "FAILED " + rr.error);
    say(m.str());
    res.runs[idx] = std::move(rr);
  });

  // 3. errors and convergence
  evaluate(res, [&](Factor f, double v, Drainage d) { return indexOf(rungSettings(config, f, v, fixedRate), d); });

  // 4. the cheapest whole settings (summed errors), each run once to measure its actual error
  std::vector<Task> checks;
  const std::pair<Output, std::vector<Drainage>> wanted[] = {{Output::Gsec, {Drainage::Undrained, Drainage::Drained}},
                                                             {Output::Du, {Drainage::Undrained}}};
  for (const auto& [output, drainages] : wanted) {
    const Combination comb = cheapestCombination(res, output, drainages);
    if (!comb.found) continue;
    for (Drainage d : drainages) {
      bool known = runWithSettings(res, comb.settings, d) >= 0;
      for (const Task& t : checks) known = known || (t.d == d && sameSettings(t.s, comb.settings));
      if (!known) checks.push_back({comb.settings, d});
    }
  }
  std::vector<RunResult> checked(checks.size());
  parallelFor(static_cast<int>(checks.size()), config.jobs, [&](int k) {
    checked[k] = runOne(config, checks[k].s, checks[k].d, specimenOf(checks[k].s.particles).info.checkpoint);
    say("  check of a combined setting (" + std::string(drainageKey(checks[k].d)) + "): " +
        (checked[k].ok ? secs(checked[k].wallSeconds) : "FAILED " + checked[k].error));
  });
  for (RunResult& rr : checked) {
    rr.id = static_cast<int>(res.runs.size());
    res.runs.push_back(std::move(rr));
  }
  res.wallSeconds = since(t0);
  res.cpuSeconds = processCpuSeconds() - cpu0;
  res.machine = machineText();
  return res;
}

}  // namespace fl::accuracy
