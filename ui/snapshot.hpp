/*
 * Snapshot: an immutable, plain-data picture of a run that the simulation worker publishes to the GUI
 * (house-style §14). It holds copies (plain std::vectors), never pointers into the Runner, so the GUI
 * thread can read it while the worker keeps stepping. Building one from a Runner is a pure function
 * (makeSnapshot); no Qt and no VTK here, so it is testable and usable anywhere.
 *
 * Per-particle mean stress (one of the colour fields) is approximated as the particle's own average
 * stress, sigma_p = (1/V_p) sum_c f_c (x) r_c with r_c the lever arm from the centre to the contact point
 * (|r_c| = r_p - delta_c/2 along n_c) and V_p = 4/3 pi r_p^3 the solid volume (no Voronoi cell). Its trace
 * only sees the normal force, so p_p = (1/(3 V_p)) sum_c F_n,c (r_p - delta_c/2) [Pa], compression positive.
 * It is larger than the continuum p' by about 1/(solid fraction); it is meant to show where the load goes.
 */
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/runner.hpp"

namespace fl::ui {

// Run state of the worker, as shown by the status line and the run controls.
enum class RunState { Empty, Ready, Running, Paused, Finished, Error };
const char* runStateName(RunState s);

struct RunStatus {
  RunState state = RunState::Empty;
  std::string sceneName;
  std::string stageName;      // "" when finished
  std::string stageType;
  int stageIndex = 0, stageCount = 0;
  long step = 0;
  double time = 0;            // simulated time [s]
  int cycle = 0;              // 1-based cycle of a cyclic stage, 0 otherwise
  double stageProgress = 0;   // 0..1
  double particleStepsPerSecond = 0;  // throughput of the worker while running [1/s]
  std::string message;        // last error or note
};

struct ContactSegment {
  std::int32_t first = 0, second = 0;  // particle indices
  Vec3 start = Vec3::Zero();           // centre of `first` [m]
  Vec3 branch = Vec3::Zero();          // to the centre of second's image [m]
  double normalForce = 0;              // [N]
};

struct Snapshot {
  long serial = 0;  // increases with every published snapshot
  RunStatus status;
  Mat3 cell = Mat3::Identity();  // H, columns are the cell vectors [m]
  // particles
  std::vector<Vec3> positions;    // wrapped into the cell [m]
  std::vector<double> radii;      // [m]
  std::vector<double> speeds;     // |v'| fluctuating speed [m/s]
  std::vector<int> contactCounts; // touching contacts per particle
  std::vector<double> meanStress; // p_p, see the header comment [Pa]
  // touching contacts only
  std::vector<ContactSegment> contacts;
  // measurements
  Sample current;  // measured at snapshot time
  bool hasCurrent = false;
  // time series (shared, immutable; the worker reuses the same vector until it grows)
  std::shared_ptr<const std::vector<Sample>> samples;
  std::shared_ptr<const std::vector<CycleRecord>> cycles;
  std::vector<StageSummary> summaries;
  std::vector<StageSpec> stages;  // the scene's protocol (drainage decides Delta u or eps_v plots)

  double meanNormalForce() const;  // over touching contacts [N], 0 without any
  std::vector<Vec3> contactNormals() const;
  std::vector<double> contactForces() const;
};

// Per-particle arrays and contact segments of a simulation state (no run information).
void fillParticles(const Simulation& sim, Snapshot& out);

// A complete snapshot of a runner. `previous` lets the time series be shared when unchanged.
// Runner::measure() is not const (it refreshes cached measures), hence the non-const runner; nothing else
// in it changes.
Snapshot makeSnapshot(Runner& runner, const RunStatus& status, const Snapshot* previous = nullptr);

}  // namespace fl::ui
