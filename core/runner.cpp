#include "runner.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <filesystem>
#include <fstream>
#include <cstring>
#include <sstream>

#include <nlohmann/json.hpp>

#include "atomic_file.hpp"
#include "binary_io.hpp"
#include "cell_control.hpp"
#include "errors.hpp"
#include "invariants.hpp"
#include "measurements.hpp"
#include "packing_io.hpp"
#include "spatial_order.hpp"
#include "vtk_xml_writer.hpp"

namespace fl {

namespace {
constexpr char kMagic[] = "FABRICLAB-CHECKPOINT";
constexpr std::uint32_t kCheckpointVersion = 1;

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

NumericsSettings resolvedNumerics(NumericsSettings n) {
  if (n.threads <= 0) n.threads = std::max(1, omp_get_num_procs());
  return n;
}

std::string slug(const std::string& s) {
  std::string o;
  for (char c : s) o += std::isalnum(static_cast<unsigned char>(c)) ? static_cast<char>(std::tolower(c)) : '-';
  return o;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

// ---- construction -------------------------------------------------------------------------------
Runner::Runner(Scene scene) : m_scene(std::move(scene)) {
  const NumericsSettings num = resolvedNumerics(m_scene.numerics);
  const auto& spec = m_scene.specimen;
  switch (spec.source) {
    case SpecimenSpec::Source::Gas:
    case SpecimenSpec::Source::Csv:
    case SpecimenSpec::Source::Lammps: {
      Packing pk;
      if (spec.source == SpecimenSpec::Source::Gas) {
        GasSpec g = spec.gas;
        g.density = m_scene.material.density;
        pk = generateGas(g);
      } else {
        pk = spec.source == SpecimenSpec::Source::Csv ? readPackingCsv(spec.path, m_scene.material.density, 0)
                                                      : readLammpsData(spec.path, 0);
      }
      // Z-order the specimen, generated or imported (issue 6): pairs and the kick's gathers stay within a
      // thread's half of the arrays and in cache. An import in arbitrary order ran the step ~1.2x (1 thread)
      // and ~1.3x (2) slower at 4000 spheres and ~2x slower at 256 000 (docs/performance.md, fifteenth
      // session). Physics is unchanged; each particle keeps its id (generation index or file row), which the
      // snapshots write.
      sortSpatially(pk.particles, pk.cell);
      m_sim = std::make_unique<Simulation>(std::move(pk.particles), pk.cell, std::vector<Material>{m_scene.material}, num);
      break;
    }
    case SpecimenSpec::Source::Checkpoint: {
      Runner source = Runner::fromCheckpoint(spec.path);  // the specimen of another run
      m_sim = std::move(source.m_sim);
      m_sim->reconfigure(m_scene.material, num);
      m_sim->setVelocityGradient(Mat3::Zero());
      break;
    }
  }
  m_configuredTimeStep = m_sim->timeStep();
}

Runner::~Runner() = default;
Runner::Runner(Runner&&) noexcept = default;
Runner& Runner::operator=(Runner&&) noexcept = default;

void Runner::removeObserver(RunObserver* o) {
  m_observers.erase(std::remove(m_observers.begin(), m_observers.end(), o), m_observers.end());
}

// ---- the stage machine --------------------------------------------------------------------------
double Runner::axialRate(const StageSpec& st) const {
  if (st.strainRate > 0) return st.strainRate;
  // I = eps_dot d sqrt(rho/p')  ->  eps_dot = I / (d sqrt(rho/p'))
  const double p = std::max(stressMeasures(m_sim->contactStress()).p, 1.0);
  const double rho = m_scene.material.density * m_sim->numerics().densityScale;
  return st.inertialNumber / (meanDiameter(m_sim->particles()) * std::sqrt(rho / p));
}

void Runner::applyFriction(double mu) {
  m_sim->setFriction(mu);
}

void Runner::startStage() {
  const StageSpec& st = m_scene.stages[m_stage];
  m_stageStarted = true;
  m_stageSteps = 0;
  m_lastSample = 0;
  m_cycle = 0;
  m_quarter = 0;
  m_lastSampleStrain = 0;
  m_stageDone = false;
  m_warned = 0;
  m_stageWallStart = wallSeconds();
  m_stageH0 = m_sim->cell().matrix();
  const StressMeasures s0 = stressMeasures(m_sim->contactStress());
  m_lateral0 = s0.lateral;
  if (st.friction >= 0) applyFriction(st.friction);

  ServoSettings servo = m_scene.servo;
  const double rho = m_scene.material.density * m_sim->numerics().densityScale;
  const double d = meanDiameter(m_sim->particles());
  auto capFor = [&](double pTarget) {
    return std::min(servo.maxStrainRate, m_scene.maxInertialNumber * std::sqrt(std::max(pTarget, 1.0) / rho) / d);
  };
  using A = AxisControl;
  std::array<AxisControl, 3> axes{};
  bool isochoric = false;
  const Mat3& sig = m_sim->contactStress();
  switch (st.type) {
    case StageType::IsotropicCompression:
      axes = {A{AxisMode::Stress, st.pressure}, A{AxisMode::Stress, st.pressure}, A{AxisMode::Stress, st.pressure}};
      servo.maxStrainRate = capFor(st.pressure);
      break;
    case StageType::Hold:
      for (int k = 0; k < 3; ++k) axes[k] = sig(k, k) > 0 ? A{AxisMode::Stress, sig(k, k)} : A{AxisMode::StrainRate, 0.0};
      servo.maxStrainRate = capFor(s0.p);
      break;
    case StageType::K0: {
      axes[0] = axes[1] = A{AxisMode::StrainRate, 0.0};
      if (st.untilIsotropic) axes[2] = A{AxisMode::Stress, s0.lateral};
      else if (st.axialStress > 0) axes[2] = A{AxisMode::Stress, st.axialStress};
      else axes[2] = A{AxisMode::MeanStress, st.pressure};
      servo.maxStrainRate = capFor(std::max({st.pressure, st.axialStress, s0.p}));
      break;
    }
    case StageType::Triaxial:
    case StageType::Cyclic: {
      m_rate = axialRate(st);
      const double sign = st.type == StageType::Triaxial && st.axialStrain < 0 ? -1.0 : 1.0;
      axes[2] = A{AxisMode::StrainRate, sign * m_rate};
      if (st.drainage == Drainage::Drained) {
        axes[0] = A{AxisMode::Stress, sig(0, 0)};
        axes[1] = A{AxisMode::Stress, sig(1, 1)};
        servo.maxStrainRate = std::max(capFor(s0.p), 10.0 * m_rate);
      } else {
        isochoric = true;
      }
      if (st.type == StageType::Cyclic) {
        m_cycle = 1;
        m_analyzer = CycleAnalyzer(s0.p, m_scene.failure);
      }
      break;
    }
  }
  m_servo = std::make_shared<AxisServo>(axes, servo, isochoric);
  m_sim->setController(m_servo);
  for (auto* o : m_observers) o->onStageStart(m_stage, st);
  takeSample();
}

void Runner::takeSample() {
  Sample s = measure();
  m_lastSample = m_stageSteps;
  m_lastSampleStrain = s.epsA;
  m_maxAxialStress = std::max(m_maxAxialStress, s.stress.z());
  const StageSpec& st = m_scene.stages[m_stage];
  if (st.type == StageType::Cyclic) m_analyzer.add({s.gamma, s.tau, s.epsA, s.q, s.p, s.du});
  m_samples.push_back(s);
  for (auto* o : m_observers) o->onSample(s);
}

void Runner::closeCycle() {
  const Sample& last = m_samples.back();
  CycleEndState end{last.epsV, last.Z, last.Zm, last.a3D, last.a2D, last.voidRatio};
  CycleRecord rec = m_analyzer.close(m_cycle, end);
  if (rec.failed && m_failureCycle == 0) m_failureCycle = m_cycle;
  m_cycles.push_back(rec);
  for (auto* o : m_observers) o->onCycle(rec);
}

void Runner::stepStage() {
  const StageSpec& st = m_scene.stages[m_stage];
  if (st.type == StageType::K0 && st.untilIsotropic) {
    // unloading: the axial target follows the lateral stress until both meet
    m_servo->setAxis(2, {AxisMode::Stress, stressMeasures(m_sim->contactStress()).lateral});
  }
  if (st.type == StageType::Triaxial || st.type == StageType::Cyclic) {
    const double epsA = -std::log(m_sim->cell().matrix()(2, 2) / m_stageH0(2, 2));
    if (st.type == StageType::Triaxial) {
      if ((st.axialStrain > 0 && epsA >= st.axialStrain) || (st.axialStrain < 0 && epsA <= st.axialStrain)) {
        m_stageDone = true;
        return;
      }
      if (m_stageSteps - m_lastSample >= m_scene.output.sampleInterval) takeSample();
      return;
    }
    const double A = st.amplitude;
    bool sample = std::abs(epsA - m_lastSampleStrain) >= 4.0 * A / st.samplesPerCycle;
    auto setRate = [&](double r) { m_servo->setAxis(2, {AxisMode::StrainRate, r}); };
    switch (m_quarter) {
      case 0:
        if (epsA >= A) { m_quarter = 1; setRate(-m_rate); sample = true; }
        break;
      case 1:
        if (epsA <= 0) m_quarter = 2;
        break;
      case 2:
        if (epsA <= -A) { m_quarter = 3; setRate(m_rate); sample = true; }
        break;
      case 3:
        if (epsA >= 0) {
          takeSample();
          closeCycle();
          if (m_cycle >= st.cycles) {
            m_stageDone = true;
            return;
          }
          ++m_cycle;
          m_quarter = 0;
          return;
        }
        break;
    }
    if (sample) takeSample();
    return;
  }
  if (m_stageSteps - m_lastSample >= m_scene.output.sampleInterval) takeSample();
}

bool Runner::stageDone() {
  if (m_stageDone) return true;
  const StageSpec& st = m_scene.stages[m_stage];
  if (st.maxSteps > 0 && m_stageSteps >= st.maxSteps) {
    std::ostringstream o;
    o << "stage " << m_stage << " '" << st.name << "' did not finish within max_steps = " << st.maxSteps
      << " (p' = " << stressMeasures(m_sim->contactStress()).p << " Pa, unbalanced force ratio "
      << m_sim->unbalancedForceRatio() << "); raise max_steps, the servo's max_strain_rate, or the tolerances";
    throw Error(o.str());
  }
  if (m_stageSteps % m_scene.output.checkInterval != 0) return false;
  switch (st.type) {
    case StageType::IsotropicCompression: return m_servo->done(*m_sim);
    case StageType::K0:
      if (st.untilIsotropic) {
        const StressMeasures s = stressMeasures(m_sim->contactStress());
        return std::abs(s.q) <= m_scene.servo.stressTolerance * s.p &&
               m_sim->unbalancedForceRatio() < m_scene.servo.unbalancedTolerance;
      }
      return m_servo->done(*m_sim);
    case StageType::Hold:
      if (st.steps > 0) return m_stageSteps >= st.steps;
      return m_sim->unbalancedForceRatio() < m_scene.servo.unbalancedTolerance;
    default: return false;
  }
}

void Runner::finishStage() {
  const StageSpec& st = m_scene.stages[m_stage];
  if (m_samples.empty() || m_samples.back().step != m_sim->stepCount()) takeSample();
  StageSummary sum;
  sum.index = m_stage;
  sum.name = st.name;
  sum.type = stageTypeName(st.type);
  sum.steps = m_stageSteps;
  sum.seconds = wallSeconds() - m_stageWallStart;
  sum.end = m_samples.back();
  sum.K0 = sum.end.stress.z() > 0 ? 0.5 * (sum.end.stress.x() + sum.end.stress.y()) / sum.end.stress.z() : 0.0;
  sum.ocr = sum.end.stress.z() > 0 ? m_maxAxialStress / sum.end.stress.z() : 0.0;
  if (st.frictionAfter >= 0) applyFriction(st.frictionAfter);
  ++m_stage;
  m_stageStarted = false;
  if (m_scene.output.checkpointAtStageEnd && !m_scene.output.directory.empty()) {
    sum.checkpoint = checkpointPath("stage-" + std::to_string(sum.index) + "-" + slug(st.name));
    writeCheckpoint(sum.checkpoint);
  }
  m_summaries.push_back(sum);
  for (auto* o : m_observers) o->onStageEnd(sum);
  if (finished())
    for (auto* o : m_observers) o->onFinished();
}

bool Runner::advance(long maxSteps) {
  for (long k = 0; k < maxSteps;) {
    if (finished()) return false;
    if (!m_stageStarted) startStage();
    // the steps before the batch's last need nothing of the runner: the engine runs them as one (Simulation::run)
    const long batch = std::min(maxSteps - k, quietSteps());
    m_sim->run(batch);
    k += batch;
    m_stageSteps += batch;
    if (!m_energyBaselineSet) {
      // after the first contact pass of this run: a specimen branched into another material carries
      // elastic energies computed with the old stiffness until then
      m_energyBalance0 = m_sim->energy().balance();
      m_energyBaselineSet = true;
    }
    checkEveryStep();
#ifdef FL_VALIDATION
    checkInvariants(*m_sim);
#endif
    if (m_stageSteps % m_scene.output.checkInterval == 0) checkPeriodically();
    stepStage();
    const OutputSpec& out = m_scene.output;
    if (!out.directory.empty()) {
      const long step = m_sim->stepCount();
      if (out.vtkInterval > 0 && step % out.vtkInterval == 0) writeVtk();
      if (out.checkpointInterval > 0 && step % out.checkpointInterval == 0) writeCheckpoint(checkpointPath("latest"));
    }
    if (stageDone()) finishStage();
  }
  return !finished();
}

// How many steps the engine may run before the runner next has something to do: every step of the batch but
// the last must be one after which advance() would only count it (no check, sample, output, reversal or end of
// stage), so that the batch gives the bits of as many single steps. Events on a step count are exact; those on
// the axial strain (reversals, the cyclic samples, a triaxial stage's end) are predicted from the strain rate,
// which the servo holds constant between them, with two steps to spare against round-off.
long Runner::quietSteps() const {
#ifdef FL_VALIDATION
  return 1;  // the invariants are checked after every step
#endif
  if (!m_energyBaselineSet) return 1;
  const StageSpec& st = m_scene.stages[m_stage];
  if (st.type == StageType::K0 && st.untilIsotropic) return 1;  // its axial target follows every step
  long quiet = std::numeric_limits<long>::max();
  auto before = [&](long stepsToEvent) { quiet = std::min(quiet, std::max(1L, stepsToEvent)); };
  // the next multiple of n after `done` steps, counted from now
  auto toMultiple = [](long done, long n) { return n - done % n; };
  const OutputSpec& out = m_scene.output;
  before(toMultiple(m_stageSteps, out.checkInterval));
  if (st.maxSteps > 0) before(st.maxSteps - m_stageSteps);
  if (!out.directory.empty()) {
    if (out.vtkInterval > 0) before(toMultiple(m_sim->stepCount(), out.vtkInterval));
    if (out.checkpointInterval > 0) before(toMultiple(m_sim->stepCount(), out.checkpointInterval));
  }
  if (st.type != StageType::Cyclic) before(m_lastSample + out.sampleInterval - m_stageSteps);
  if (st.type == StageType::Triaxial || st.type == StageType::Cyclic) {
    const double epsA = -std::log(m_sim->cell().matrix()(2, 2) / m_stageH0(2, 2));
    const double perStep = -m_sim->cell().velocityGradient()(2, 2) * m_sim->timeStep();  // d eps_a per step
    // steps that certainly stay short of `target` (none left if the strain is there already)
    auto toStrain = [&](double target) {
      const double steps = (target - epsA) / perStep;
      if (steps > 0 && std::isfinite(steps)) before(static_cast<long>(std::min(steps, 1e15)) - 2);
    };
    if (st.type == StageType::Triaxial) {
      toStrain(st.axialStrain);
    } else {
      const double A = st.amplitude, every = 4.0 * A / st.samplesPerCycle;
      toStrain(m_lastSampleStrain + every);
      toStrain(m_lastSampleStrain - every);
      const double thresholds[4] = {A, 0.0, -A, 0.0};  // of quarters 0-3 (stepStage)
      toStrain(thresholds[m_quarter]);
    }
  }
  return quiet;
}

double Runner::stageProgress() const {
  if (finished()) return 1.0;
  const StageSpec& st = m_scene.stages[m_stage];
  if (!m_stageStarted) return 0.0;
  const double epsA = -std::log(m_sim->cell().matrix()(2, 2) / m_stageH0(2, 2));
  switch (st.type) {
    case StageType::Triaxial: return std::clamp(epsA / st.axialStrain, 0.0, 1.0);
    case StageType::Cyclic: {
      const double quarterDone = m_quarter + (m_quarter % 2 == 0 ? std::abs(epsA) : st.amplitude - std::abs(epsA)) / st.amplitude;
      return std::clamp(((m_cycle - 1) + quarterDone / 4.0) / st.cycles, 0.0, 1.0);
    }
    case StageType::Hold: return st.steps > 0 ? std::min(1.0, double(m_stageSteps) / st.steps) : 0.0;
    default: {
      const double p = stressMeasures(m_sim->contactStress()).p;
      const double target = st.pressure > 0 ? st.pressure : st.axialStress;
      return target > 0 ? std::clamp(p / target, 0.0, 1.0) : 0.0;
    }
  }
}

// ---- guards (issue: numerical stability) -----------------------------------------------------------
// O(1) per step: non-finite stress or cell.
void Runner::checkEveryStep() {
  const Simulation& sim = *m_sim;
  const Mat3& s = sim.contactStress();
  if (!s.allFinite() || !sim.cell().matrix().allFinite())
    blowUp("NaN/Inf in the stress or the cell", "reduce numerics.time_step_factor or enable guards.adaptive_time_step");
}

// Every check interval: runaway overlap; the time step follows the contact stiffness; energy must not be
// created. The overlap and the stiffness are read off the stored contacts (Simulation::diagnostics), O(pairs),
// so not every step.
void Runner::checkPeriodically() {
  Simulation& sim = *m_sim;
  const GuardSettings& g = m_scene.guards;
  const double ov = sim.diagnostics().maxOverlapRatio;
  if (!(ov <= m_scene.guards.maxOverlapRatio)) {
    std::ostringstream o;
    o << "an overlap reached " << ov << " of the particle radius (limit guards.max_overlap_ratio = "
      << m_scene.guards.maxOverlapRatio << ")";
    blowUp(o.str(), "the particles are too soft for this stress or the loading too fast: raise material.shear_modulus, "
                    "lower the target stress or the strain rate, or raise guards.max_overlap_ratio if intended");
  }
  if (g.adaptiveTimeStep) {
    const double limit = g.stiffnessSafety * sim.stiffnessTimeStep();
    const double want = std::min(m_configuredTimeStep, limit);
    // shrink at once, grow back only by a clear margin (avoids flapping)
    if (want < sim.timeStep() || want > 1.05 * sim.timeStep()) {
      if (want < sim.timeStep()) {
        std::ostringstream o;
        o << "time step reduced to " << want << " s (contacts stiffened: stiffness-based critical step "
          << sim.stiffnessTimeStep() << " s)";
        warnOnce(1, o.str());
      }
      sim.setTimeStep(want);
      ++m_timeStepChanges;
    }
  }
  if (sim.numerics().trackEnergy && m_energyBaselineSet) {
    const EnergyLedger& en = sim.energy();
    const double scale = std::max({std::abs(en.boundaryWork), en.dissipated(), en.stored(), 1e-300});
    const double err = std::abs(en.balance() - m_energyBalance0) / scale;
    if (!std::isfinite(err)) blowUp("NaN/Inf in the energy (a particle's velocity or position)",
                                    "reduce numerics.time_step_factor or enable guards.adaptive_time_step");
    if (err > g.maxEnergyError && en.balance() > m_energyBalance0) {
      std::ostringstream o;
      o << "the energy balance broke: " << err << " of the energy turnover was created (limit guards.max_energy_error = "
        << g.maxEnergyError << ")";
      blowUp(o.str(), "reduce numerics.time_step_factor, enable guards.adaptive_time_step, or add damping");
    }
    if (err > g.warnEnergyError) {
      std::ostringstream o;
      o << "energy balance error " << err << " exceeds guards.warn_energy_error = " << g.warnEnergyError;
      warnOnce(2, o.str());
    }
  }
  const StageSpec* st = currentStage();
  if (st && m_stageStarted) {
    const double p = stressMeasures(sim.contactStress()).p;
    const double I = inertialNumber(sim, p);
    if (p > 0 && I > g.warnInertialNumber && m_sim->diagnostics().contacts > 0) {
      std::ostringstream o;
      o << "stage '" << st->name << "' runs at inertial number " << I << " > " << g.warnInertialNumber
        << ": not quasi-static; lower the strain rate or the servo's max_inertial_number";
      warnOnce(4, o.str());
    }
  }
}

void Runner::warnOnce(int kind, const std::string& message) {
  if (m_warned & kind) return;
  m_warned |= kind;
  for (auto* o : m_observers) o->onWarning(message);
}

void Runner::blowUp(const std::string& cause, const std::string& fix) {
  std::ostringstream o;
  o << "numerical instability at step " << m_sim->stepCount() << " (t = " << m_sim->time() << " s, dt = "
    << m_sim->timeStep() << " s, stage '" << (currentStage() ? currentStage()->name : std::string("-"))
    << "'): " << cause << ". To fix: " << fix << ".";
  if (!m_scene.output.directory.empty()) {
    const std::string ck = checkpointPath("diagnostic-step-" + std::to_string(m_sim->stepCount()));
    try {
      writeCheckpoint(ck);
      o << " Diagnostic checkpoint: " << ck;
    } catch (const std::exception& e) {
      o << " (diagnostic checkpoint failed: " << e.what() << ")";
    }
  }
  throw InstabilityError(o.str());
}

// ---- measurement --------------------------------------------------------------------------------
Sample Runner::measure() {
  Simulation& sim = *m_sim;
  Sample s;
  s.step = sim.stepCount();
  s.time = sim.time();
  s.stage = std::min(m_stage, stageCount() - 1);
  s.cycle = m_cycle;
  const StressMeasures st = stressMeasures(sim.contactStress());
  s.stress = sim.contactStress().diagonal();
  s.p = st.p;
  s.q = st.q;
  s.tau = st.tau;
  const StrainMeasures e = strainMeasures(sim.cell(), m_stageStarted ? m_stageH0 : sim.cell().matrix());
  s.epsA = e.axial;
  s.epsR = e.radial;
  s.epsV = e.volumetric;
  s.gamma = e.shear;
  s.voidRatio = voidRatio(sim);
  const ContactCounts z = contactCounts(sim);
  s.Z = z.coordination;
  s.Zm = z.mechanicalCoordination;
  const FabricMeasures f = fabricMeasures(sim);
  s.a3D = f.anisotropy3D;
  s.a2D = f.anisotropy2D;
  const StageSpec* cur = currentStage();
  if (cur && m_stageStarted && (cur->type == StageType::Triaxial || cur->type == StageType::Cyclic) &&
      cur->drainage == Drainage::Undrained)
    s.du = m_lateral0 - st.lateral;  // constant total cell pressure: du = sigma'_3,0 - sigma'_3
  s.inertialNumber = inertialNumber(sim, st.p);
  s.unbalanced = sim.unbalancedForceRatio();
  const EnergyLedger& en = sim.energy();
  s.kinetic = en.kinetic;
  s.elastic = en.elasticNormal + en.elasticTangential;
  s.dissipated = en.dissipated();
  s.boundaryWork = en.boundaryWork;
  const double scale = std::max({std::abs(en.boundaryWork), en.dissipated(), en.stored(), 1e-300});
  s.energyError = m_energyBaselineSet ? std::abs(en.balance() - m_energyBalance0) / scale : 0.0;
  s.timeStep = sim.timeStep();
  s.timeStepMargin = sim.timeStep() / sim.stiffnessTimeStep();
  s.friction = sim.materials()[0].friction;
  return s;
}

// ---- outputs: ParaView snapshots and checkpoints ---------------------------------------------------
std::string Runner::checkpointPath(const std::string& tag) const {
  return (std::filesystem::path(m_scene.output.directory) / "checkpoints" / (tag + ".ckpt")).string();
}

void Runner::writeVtk() {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(m_scene.output.directory) / "paraview";
  fs::create_directories(dir);
  const std::string stem = "step-" + std::to_string(m_sim->stepCount());
  writeParticlesVtu((dir / (stem + "-particles.vtu")).string(), *m_sim);
  writeContactsVtu((dir / (stem + "-contacts.vtu")).string(), *m_sim);
  writeCellVtu((dir / (stem + "-cell.vtu")).string(), m_sim->cell());
  static const char* kSeries[3] = {"particles", "contacts", "cell"};
  for (int k = 0; k < 3; ++k) {
    if (!m_pvd[k]) m_pvd[k] = std::make_unique<PvdCollection>((dir / (std::string(kSeries[k]) + ".pvd")).string());
    m_pvd[k]->add(m_sim->time(), stem + "-" + kSeries[k] + ".vtu");
  }
}

void Runner::writeCheckpoint(const std::string& path) const {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  BinaryWriter w;
  w.putString(sceneToJson(m_scene));
  w.put(m_stage);
  w.put(m_stageStarted);
  w.put(m_stageSteps);
  w.put(m_lastSample);
  for (int k = 0; k < 9; ++k) w.put(m_stageH0.data()[k]);
  w.put(m_lateral0);
  w.put(m_rate);
  w.put(m_cycle);
  w.put(m_quarter);
  w.put(m_lastSampleStrain);
  w.put(m_maxAxialStress);
  w.put(m_failureCycle);
  w.put(m_stageDone);
  w.put(m_energyBalance0);
  w.put(m_energyBaselineSet);
  w.put(m_configuredTimeStep);
  w.put(m_timeStepChanges);
  w.put(m_analyzer.initialPressure());
  w.put(m_analyzer.firstStiffness());
  w.put(m_analyzer.failure());
  w.putVector(m_analyzer.points());
  w.putVector(m_cycles);
  const bool servo = static_cast<bool>(m_servo);
  w.put(servo);
  if (servo) {
    for (int k = 0; k < 3; ++k) w.put(m_servo->axis(k));
    w.put(m_servo->settings());
    w.put(m_servo->isochoric());
    w.put(m_servo->strainRate());
  }
  m_sim->saveState(w);
  const std::string& payload = w.bytes();
  std::string file(kMagic, sizeof(kMagic));
  BinaryWriter head;
  head.put(kCheckpointVersion);
  head.put<std::uint64_t>(payload.size());
  file += head.bytes();
  file += payload;
  BinaryWriter tail;
  tail.put(fnv1a64(payload));
  file += tail.bytes();
  writeFileAtomically(path, file);
}

namespace {
// Splits a checkpoint file into its payload after checking magic, version, size and checksum.
std::string checkpointPayload(const std::string& path, const std::string& bytes) {
  const std::size_t headSize = sizeof(kMagic) + sizeof(std::uint32_t) + sizeof(std::uint64_t);
  if (bytes.size() < headSize + sizeof(std::uint64_t) || bytes.compare(0, sizeof(kMagic), std::string(kMagic, sizeof(kMagic))) != 0)
    throw IoError(path + ": not a FabricLab checkpoint (bad magic at byte 0)");
  BinaryReader head(bytes.substr(sizeof(kMagic), headSize - sizeof(kMagic)), path, sizeof(kMagic));
  const auto version = head.get<std::uint32_t>("version");
  if (version != kCheckpointVersion)
    throw IoError(path + ": checkpoint version " + std::to_string(version) + " is not supported (this build reads " +
                  std::to_string(kCheckpointVersion) + ")");
  const auto size = head.get<std::uint64_t>("payload size");
  if (size != bytes.size() - headSize - sizeof(std::uint64_t))
    throw IoError(path + ": truncated or padded checkpoint: header says " + std::to_string(size) + " payload bytes, file has " +
                  std::to_string(bytes.size() - headSize - sizeof(std::uint64_t)));
  std::string payload = bytes.substr(headSize, size);
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + headSize + size, sizeof(stored));
  if (stored != fnv1a64(payload)) throw IoError(path + ": checkpoint checksum mismatch (corrupted file)");
  return payload;
}

}  // namespace

Runner Runner::fromCheckpoint(const std::string& path) {
  const std::string bytes = readFile(path);
  const std::string payload = checkpointPayload(path, bytes);
  const std::size_t base = sizeof(kMagic) + sizeof(std::uint32_t) + sizeof(std::uint64_t);
  BinaryReader r(payload, path, base);
  Runner run;
  const std::string sceneText = r.getString("scene");
  try {
    run.m_scene = parseScene(nlohmann::json::parse(sceneText), path + " (embedded scene)");
  } catch (const nlohmann::json::exception& e) {
    r.fail(std::string("embedded scene is not valid JSON: ") + e.what());
  }
  run.m_stage = r.get<int>("stage index");
  run.m_stageStarted = r.get<bool>("stage started");
  run.m_stageSteps = r.get<long>("stage steps");
  run.m_lastSample = r.get<long>("last sample");
  for (int k = 0; k < 9; ++k) run.m_stageH0.data()[k] = r.get<double>("stage reference");
  run.m_lateral0 = r.get<double>("lateral stress at stage start");
  run.m_rate = r.get<double>("strain rate");
  run.m_cycle = r.get<int>("cycle");
  run.m_quarter = r.get<int>("quarter");
  run.m_lastSampleStrain = r.get<double>("last sample strain");
  run.m_maxAxialStress = r.get<double>("max axial stress");
  run.m_failureCycle = r.get<int>("failure cycle");
  run.m_stageDone = r.get<bool>("stage done");
  run.m_energyBalance0 = r.get<double>("initial energy balance");
  run.m_energyBaselineSet = r.get<bool>("energy baseline set");
  run.m_configuredTimeStep = r.get<double>("configured time step");
  run.m_timeStepChanges = r.get<long>("time step changes");
  if (!(run.m_configuredTimeStep > 0)) r.fail("configured time step must be > 0");
  const double p0 = r.get<double>("cycle p0");
  const double g1 = r.get<double>("cycle G1");
  const FailureCriteria fc = r.get<FailureCriteria>("failure criteria");
  auto pts = r.getVector<CyclePoint>("cycle points");
  run.m_analyzer.restore(p0, g1, fc, std::move(pts));
  run.m_cycles = r.getVector<CycleRecord>("cycle records");
  for (const CycleRecord& c : run.m_cycles) {  // inspect the flag's byte without loading it as a bool
    unsigned char b;
    std::memcpy(&b, &c.failed, 1);
    if (b > 1) r.fail("invalid failure flag in the cycle records");
  }
  if (run.m_stage < 0 || run.m_stage > static_cast<int>(run.m_scene.stages.size()) || run.m_quarter < 0 || run.m_quarter > 3)
    r.fail("invalid stage state");
  const bool servo = r.get<bool>("servo present");
  std::array<AxisControl, 3> axes{};
  ServoSettings ss;
  bool iso = false;
  Vec3 rate = Vec3::Zero();
  if (servo) {
    for (int k = 0; k < 3; ++k) {
      axes[k] = r.get<AxisControl>("servo axis");
      int mode;
      std::memcpy(&mode, &axes[k].mode, sizeof mode);
      if (mode < 0 || mode > static_cast<int>(AxisMode::MeanStress)) r.fail("invalid servo axis mode");
    }
    ss = r.get<ServoSettings>("servo settings");
    iso = r.get<bool>("servo isochoric");
    rate = r.get<Vec3>("servo strain rate");
  }
  run.m_sim = std::make_unique<Simulation>(Simulation::restoreState(r));
  if (!r.atEnd()) r.fail("unexpected data after the simulation state");
  if (servo) {
    try {
      run.m_servo = std::make_shared<AxisServo>(axes, ss, iso);
    } catch (const InputError& e) {
      r.fail(std::string("invalid servo state: ") + e.what());
    }
    run.m_servo->setStrainRate(rate);
    // install without re-evaluating (the saved L is already the one for the next step)
    const Mat3 L = run.m_sim->cell().velocityGradient();
    run.m_sim->setController(run.m_servo);
    run.m_sim->setVelocityGradient(L);
  }
  run.m_stageWallStart = wallSeconds();
  return run;
}

}  // namespace fl
