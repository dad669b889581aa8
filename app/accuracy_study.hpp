// Accuracy against cost (issue 7, part 1): how far the paper's cyclic results move when a numerical
// setting is made cheaper, and what each setting costs in wall time.
//
// One specimen per particle count is prepared once (gas -> 50 kPa with compression friction 0.02 ->
// 318 kPa, glass beads of the paper) and saved as a checkpoint; every run branches from it (specimen source
// "checkpoint"), so runs differ only in the setting under study. Each run applies the first cycles of the
// strain-controlled cyclic test (eps_a = +-0.023 %), undrained and drained. Ladders vary one factor at a
// time from a base (the paper's cyclic numerics): inertial number, time_step_factor, local damping,
// contact damping (restitution), density scaling (at a fixed physical strain rate), particle count.
//
// Errors: for each output x (a list of values over the cycles, e.g. G_sec of cycles 1..n, or p' at both
// reversals of every cycle) the relative error of a run against its ladder's reference is
//   err = max_k |x_k - x_ref,k| / max_k |x_ref,k|,
// the reference being the finest rung of the ladder. The reference is called converged for an output when
// the two finest rungs agree within `convergenceTolerance` (the same formula), or when the finest rung is the
// exact limit of the factor (no local damping, no contact damping, no density scaling). Particle count is not a
// numerical parameter: its "error" against the largest count is a size effect (a different specimen).
//
// This module has no Qt: plots are described as PlotSpec values and drawn by a callback (fl_charts in the
// executable). Results do not depend on the number of parallel jobs (each run is deterministic).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace fl::accuracy {

enum class Factor { InertialNumber, TimeStepFactor, LocalDamping, Restitution, DensityScale, ParticleCount };
const char* factorKey(Factor f);    // "inertial_number", ... (CSV)
const char* factorTitle(Factor f);  // "inertial number", ... (report)
bool isNumerical(Factor f);         // false for ParticleCount (a size effect)

enum class Drainage { Undrained, Drained };
const char* drainageKey(Drainage d);

// The outputs compared between runs.
enum class Output { Gsec, PReversal, QReversal, Du, EpsV, Z, A, Count };
const char* outputKey(Output o);    // CSV column suffix
const char* outputTitle(Output o);  // report
bool appliesTo(Output o, Drainage d);  // du: undrained only; eps_v: drained only
constexpr int kOutputCount = static_cast<int>(Output::Count);

struct Settings {
  double inertialNumber = 1e-4;  // [-]
  double timeStepFactor = 0.25;  // [-]
  double localDamping = 0.05;    // [-]
  double restitution = 1.0;      // [-] (1: no contact damping)
  double densityScale = 1.0;     // [-]
  int particles = 1000;
  double strainRate = 0.0;       // [1/s]; > 0 overrides inertialNumber (density ladder: fixed physical rate)
  double value(Factor f) const;
  void set(Factor f, double v);
};

// One factor's rungs, ordered from the coarsest (cheapest or most perturbed) to the finest (reference).
struct Ladder {
  Factor factor;
  std::vector<double> values;
};

struct StudyConfig {
  Settings base;
  std::vector<Ladder> ladders;
  int cycles = 2;
  double amplitude = 2.3e-4;      // single amplitude of eps_a [-]
  double pressure = 318e3;        // p' of the specimen [Pa]
  int samplesPerCycle = 40;
  double convergenceTolerance = 0.005;  // the two finest rungs must agree within this fraction [-]
  double target = 0.01;           // "cheapest setting with error below this" [-]
  std::uint64_t seed = 1;
  int jobs = 1;
  bool quick = false;
};
StudyConfig fullConfig();   // the study shipped in docs/accuracy-vs-cost.md
StudyConfig quickConfig();  // CI: 400 spheres, 1 cycle, tiny ladders

// What one run measured (per-cycle values in cycle order).
struct Metrics {
  std::vector<double> Gsec;          // [Pa]
  std::vector<double> pReversal;     // p' at +A then -A, every cycle [Pa]
  std::vector<double> qReversal;     // q at +A then -A, every cycle [Pa]
  std::vector<double> du;            // excess pore pressure at the end of every cycle [Pa] (undrained)
  std::vector<double> epsV;          // volumetric strain at the end of every cycle [-] (drained)
  std::vector<double> Z;             // coordination number at the end of every cycle [-]
  std::vector<double> a;             // a_2D (Rothenburg–Bathurst) at the end of every cycle [-]
  const std::vector<double>& of(Output o) const;
  std::vector<double>& of(Output o);
};

struct RunResult {
  int id = 0;                 // index in StudyResult::runs
  Settings settings;
  Drainage drainage = Drainage::Undrained;
  bool ok = false;
  std::string error;          // why it failed (instability, ...)
  Metrics metrics;
  double wallSeconds = 0;     // cyclic stage, wall [s]
  double cpuSeconds = 0;      // cyclic stage, CPU of the run's thread [s]
  long steps = 0;
  long particleSteps = 0;
  double maxInertialNumber = 0, maxEnergyError = 0, dtOverRayleigh = 0;
};

// A row of the study: one rung of one ladder for one drainage, pointing at a run (the base run is shared
// by every ladder) and holding its errors against the ladder's reference (NaN where not applicable).
struct Row {
  Factor factor;
  double value = 0;
  Drainage drainage = Drainage::Undrained;
  int run = -1;
  bool reference = false;
  bool base = false;
  double errors[kOutputCount];
};

// Convergence of one ladder's reference for one drainage and output.
struct Convergence {
  Factor factor;
  Drainage drainage;
  Output output;
  double finest = 0, second = 0;  // rung values
  double disagreement = 0;        // err(second finest vs finest) [-]
  // The finest rung is the exact limit itself (local damping 0, restitution 1, density scale 1): the
  // reference has no error in this factor by construction; the disagreement then measures sensitivity.
  bool exactLimit = false;
  bool converged = false;         // exactLimit, or disagreement <= convergenceTolerance
};
bool isExactLimit(Factor f, double value);

struct SpecimenInfo {
  int particles = 0;
  std::string checkpoint;
  double p = 0, voidRatio = 0, Z = 0, a2D = 0, meanDiameter = 0;
  double prepareSeconds = 0;
};

struct StudyResult {
  StudyConfig config;
  std::vector<SpecimenInfo> specimens;
  std::vector<RunResult> runs;
  std::vector<Row> rows;
  std::vector<Convergence> convergence;
  double wallSeconds = 0, cpuSeconds = 0;  // the whole study (process CPU) [s]
  std::string machine;                     // cores, load average (for the report)
  double fixedRate = 0;  // physical strain rate of the density-scaling ladder (base I, no scaling) [1/s]
  std::string command;   // the command that measured it (kept in results.json)
};

// The settings of one rung: the base with `factor` set to `value`; density-scaling rungs other than the
// base's keep the physical strain rate `fixedRate`.
Settings rungSettings(const StudyConfig& c, Factor factor, double value, double fixedRate);
// The run id of a rung (throws fl::Error if absent).
int findRun(const StudyResult& r, Factor factor, double value, Drainage drainage);

// ---- pure functions (tested on synthetic data) --------------------------------------------------------
// max_k |v_k - r_k| / max_k |r_k|; NaN when the sizes differ, either is empty or max |r| = 0.
double relativeError(const std::vector<double>& v, const std::vector<double>& ref);
// Indices of the points not dominated by another (cost <= and error <=, one strictly), sorted by cost.
// Points with a non-finite cost or error are ignored.
std::vector<std::size_t> paretoFront(const std::vector<double>& cost, const std::vector<double>& error);
// Fills rows and convergence from runs (the runs of every rung must be present in `runIndex`).
// `runIndex(factor, value, drainage)` returns the run id of that rung.
void evaluate(StudyResult& r, const std::function<int(Factor, double, Drainage)>& runIndex);

// Cheapest single rung of the numerical ladders (fewest particle-steps, then lowest error) whose own error on
// `output` is below the target for every drainage given, counting only ladders whose reference is
// converged for that output. This is the error due to that factor alone (the others at the base).
struct Cheapest {
  bool found = false;
  Factor factor = Factor::InertialNumber;
  double value = 0;
  double particleSteps = 0;           // summed over the drainages considered
  double wallSeconds = 0;             // summed over the drainages considered [s]
  double worstError = 0;              // over those drainages [-]
  double referenceWallSeconds = 0;    // the ladder reference, same drainages [s]
};
Cheapest cheapestBelow(const StudyResult& r, Output output, const std::vector<Drainage>& drainages);

// The cheapest whole setting: one rung per numerical ladder. To first order the errors of the factors add,
// so a setting's error is bounded by the sum of its rungs' errors, each against its own ladder's reference
// (a factor left at the base contributes the base rung's error). Its cost is the base run's particle-steps
// times the step ratio of each rung. Inertial number and density scaling both set the effective inertial
// number, so a setting changes at most one of them. Requires every numerical ladder's reference to be
// converged (or an exact limit) for the output; `reason` says why nothing was found.
struct Combination {
  bool found = false;
  std::string reason;
  Settings settings;                  // strainRate set for a scaled density
  std::vector<std::pair<Factor, double>> rungs;
  double bound = 0;                   // max over the drainages of the summed errors [-]
  double costRatio = 0;               // predicted particle-steps / the base run's [-]
  double baseBound = 0;               // the same bound for the base setting [-]
};
Combination cheapestCombination(const StudyResult& r, Output output, const std::vector<Drainage>& drainages);
// The additive estimate of the result converged in every numerical factor:
// x_conv = x_base - sum_f (x_base - x_ref,f), per cycle value. Empty if a run is missing.
std::vector<double> extrapolatedReference(const StudyResult& r, Output output, Drainage drainage);
// The run of the base setting, and of any setting (-1 if absent).
int baseRun(const StudyResult& r, Drainage drainage);
int runWithSettings(const StudyResult& r, const Settings& s, Drainage drainage);

// ---- outputs -------------------------------------------------------------------------------------------
std::string csvText(const StudyResult& r);     // one row per rung and drainage
nlohmann::json resultJson(const StudyResult& r);  // everything, per-cycle values included
StudyResult resultFromJson(const nlohmann::json& j);  // and back (rows and convergence re-evaluated)

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  bool markers = true;
};
struct PlotSpec {
  std::string file;  // name inside the image folder, e.g. "gsec-undrained.png"
  std::string title, xLabel, yLabel;
  bool logX = true, logY = true;
  std::vector<PlotSeries> series;
};
std::vector<PlotSpec> plots(const StudyResult& r);
// The Markdown report. `imageDir` is the image folder relative to the report; `images` the files that were
// actually drawn (an empty list: no plot section, and the report says why); `command` the command writing it
// (named as well when it differs from the one that measured the results, r.command).
std::string reportMarkdown(const StudyResult& r, const std::string& imageDir, const std::vector<std::string>& images,
                           const std::string& command);

// ---- running -------------------------------------------------------------------------------------------
// Prepares the specimens (in workDir/specimens/N) and runs every rung; progress lines go to `log`.
StudyResult runStudy(const StudyConfig& config, const std::string& workDir,
                     const std::function<void(const std::string&)>& log);

}  // namespace fl::accuracy
