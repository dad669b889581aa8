// The runner executes a scene: it builds the specimen, runs the stages in order on one Simulation,
// measures on its own schedule (never every step), analyses cycles, and tells observers.
// Used by the headless command (outputs are an observer) and by the GUI worker thread (snapshots are an
// observer). Not thread-safe: one thread owns a Runner.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "cycle_analysis.hpp"
#include "energy_ledger.hpp"
#include "scene.hpp"
#include "simulation.hpp"

namespace fl {

class AxisServo;
class PvdCollection;

// One time-series record. Strains are measured from the start of the current stage.
struct Sample {
  long step = 0;
  double time = 0;                   // [s]
  int stage = 0;                     // stage index
  int cycle = 0;                     // 1-based cycle in a cyclic stage, 0 otherwise
  Vec3 stress = Vec3::Zero();        // sigma'_xx, yy, zz [Pa]
  double p = 0, q = 0, tau = 0;      // [Pa]
  double epsA = 0, epsR = 0, epsV = 0, gamma = 0;  // [-]
  double voidRatio = 0, Z = 0, Zm = 0;
  double a3D = 0, a2D = 0;           // fabric anisotropy, both definitions (measurements.hpp)
  double du = 0;                     // excess pore pressure (constant-volume stages) [Pa]
  double inertialNumber = 0, unbalanced = 0;
  double kinetic = 0, elastic = 0, dissipated = 0, boundaryWork = 0;  // [J]
  double energyError = 0;            // |balance drift| / max(boundary work, dissipated, stored) [-]
  double timeStep = 0, timeStepMargin = 0;  // dt [s], dt / (stiffness-based critical step) [-]
  double friction = 0;
};

struct StageSummary {
  int index = 0;
  std::string name, type;
  long steps = 0;
  double seconds = 0;    // wall time [s]
  Sample end;            // state at the end
  double K0 = 0;         // sigma'_h / sigma'_v at the end
  double ocr = 0;        // sigma'_v,max (whole run) / sigma'_v at the end
  std::string checkpoint;  // file written at the end ("" if none)
};

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  virtual void onStageStart(int /*index*/, const StageSpec& /*stage*/) {}
  virtual void onSample(const Sample& /*s*/) {}
  virtual void onCycle(const CycleRecord& /*c*/) {}
  virtual void onStageEnd(const StageSummary& /*s*/) {}
  virtual void onFinished() {}
  // Run-time honesty: leaving the quasi-static regime, energy drift, time-step changes (once per kind
  // and stage).
  virtual void onWarning(const std::string& /*message*/) {}
};

class Runner {
 public:
  explicit Runner(Scene scene);  // builds the specimen (gas, checkpoint or packing file)
  ~Runner();
  Runner(Runner&&) noexcept;
  Runner& operator=(Runner&&) noexcept;
  // Restores a run from a checkpoint (scene, stage, controller, cycle state, simulation) bit-exactly.
  static Runner fromCheckpoint(const std::string& path);

  void addObserver(RunObserver* o) { m_observers.push_back(o); }
  void removeObserver(RunObserver* o);

  // Runs at most maxSteps steps (stops early at the end of the run). Returns false once finished.
  bool advance(long maxSteps);
  bool finished() const { return m_stage >= static_cast<int>(m_scene.stages.size()); }

  const Scene& scene() const { return m_scene; }
  const Simulation& simulation() const { return *m_sim; }
  int stageIndex() const { return m_stage; }
  int stageCount() const { return static_cast<int>(m_scene.stages.size()); }
  const StageSpec* currentStage() const { return finished() ? nullptr : &m_scene.stages[m_stage]; }
  int currentCycle() const { return m_cycle; }
  double stageProgress() const;  // 0..1 estimate for the current stage (strain or stress distance)

  Sample measure();  // measures now (does not notify or store)
  const std::vector<Sample>& samples() const { return m_samples; }
  const std::vector<CycleRecord>& cycles() const { return m_cycles; }
  const std::vector<StageSummary>& summaries() const { return m_summaries; }
  int failureCycle() const { return m_failureCycle; }  // first failed cycle, 0 if none

  void writeCheckpoint(const std::string& path) const;
  std::string checkpointPath(const std::string& tag) const;  // in the output directory

 private:
  Runner() = default;
  void startStage();
  void finishStage();
  void stepStage();
  long quietSteps() const;  // steps that may run as one batch (advance)
  void takeSample();
  bool stageDone();
  void closeCycle();
  double axialRate(const StageSpec& st) const;
  void applyFriction(double mu);
  void writeVtk();
  void checkEveryStep();
  void checkPeriodically();
  [[noreturn]] void blowUp(const std::string& cause, const std::string& fix);
  void warnOnce(int kind, const std::string& message);

  Scene m_scene;
  std::unique_ptr<Simulation> m_sim;
  std::shared_ptr<AxisServo> m_servo;
  std::vector<RunObserver*> m_observers;
  std::vector<Sample> m_samples;
  std::vector<CycleRecord> m_cycles;
  std::vector<StageSummary> m_summaries;
  // stage state (saved in checkpoints)
  int m_stage = 0;
  bool m_stageStarted = false;
  long m_stageSteps = 0;
  long m_lastSample = 0;
  Mat3 m_stageH0 = Mat3::Identity();  // cell matrix at stage start (strain reference)
  double m_lateral0 = 0;              // sigma'_3 at stage start (pore pressure reference)
  double m_rate = 0;                  // axial strain rate of strain-controlled stages [1/s]
  int m_cycle = 0;                    // current cycle (1-based) in a cyclic stage
  int m_quarter = 0;                  // 0: 0->+A, 1: +A->0, 2: 0->-A, 3: -A->0
  double m_lastSampleStrain = 0;
  double m_maxAxialStress = 0;
  int m_failureCycle = 0;
  double m_stageWallStart = 0;
  bool m_stageDone = false;
  double m_energyBalance0 = 0;        // energy balance after the first step of the run
  bool m_energyBaselineSet = false;
  CycleAnalyzer m_analyzer;
  std::array<std::unique_ptr<PvdCollection>, 3> m_pvd;
  double m_configuredTimeStep = 0;    // dt from the scene; the adaptive step never exceeds it [s]
  long m_timeStepChanges = 0;
  unsigned m_warned = 0;              // bit per warning kind, reset at each stage
 public:
  long timeStepChanges() const { return m_timeStepChanges; }  // particles, contacts, cell series
};

}  // namespace fl
