#include "headless.hpp"

#include <omp.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/measurements.hpp"
#include "core/packing_io.hpp"
#include "core/run_outputs.hpp"
#include "core/runner.hpp"
#include "core/scene.hpp"

namespace fl::app {

namespace {

std::atomic<int> g_signal{0};
extern "C" void onSignal(int s) { g_signal.store(s); }

// Prints run-time warnings (leaving the quasi-static regime, energy drift, time-step changes).
class WarningPrinter final : public RunObserver {
 public:
  void onWarning(const std::string& m) override { std::fprintf(stderr, "\nwarning: %s\n", m.c_str()); }
};

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: fabriclab-run SCENE.json [options]      run a scene headless\n"
               "       fabriclab-run --restart CHECKPOINT [options]  continue a run from a checkpoint\n"
               "       fabriclab-run --schema-doc [FILE]          write the scene-file reference (Markdown)\n"
               "options:\n"
               "  --out DIR          results folder (overrides the scene's output.directory)\n"
               "  --overwrite        replace the results of a previous run in a non-empty folder\n"
               "  --threads N        OpenMP threads (results do not depend on it)\n"
               "  --export-csv FILE  write the final packing as CSV (x,y,z,r)\n"
               "  --export-lammps FILE  write the final packing as a LAMMPS data file (atom_style sphere)\n"
               "  --quiet            no progress line\n");
}

// Refuses a results folder that exists and is not empty (unless overwrite), or that cannot be written,
// before the run starts rather than after an hour.
// What to do with a results folder that already holds files.
enum class ExistingResults {
  Refuse,   // a fresh run without --overwrite
  Keep,     // --restart: the run continues its own results (the time series are append logs)
  Replace,  // a fresh run with --overwrite: FabricLab's previous results go, other files stay
};

void prepareOutputDirectory(const std::string& dir, ExistingResults existing) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) throw IoError(dir + ": exists and is not a folder");
  if (fs::exists(dir, ec) && !fs::is_empty(dir, ec)) {
    if (existing == ExistingResults::Refuse)
      throw IoError(dir + ": results folder is not empty; choose another --out or pass --overwrite");
    // A fresh run replaces FabricLab's own results (the time series are append logs, kept across restarts,
    // so they must go); anything else the user keeps in the folder stays.
    const std::vector<const char*> ours = {"timeseries.csv", "cycles.csv", "warnings.txt", "stages.json",
                                           "scene.json", "checkpoints", "paraview"};
    for (const char* name : existing == ExistingResults::Replace ? ours : std::vector<const char*>{}) {
      const fs::path p = fs::path(dir) / name;
      if (fs::exists(p, ec) && fs::remove_all(p, ec) == static_cast<std::uintmax_t>(-1))
        throw IoError(p.string() + ": cannot remove the previous result (--overwrite): " + ec.message());
    }
  }
  fs::create_directories(dir, ec);
  if (ec) throw IoError(dir + ": cannot create the results folder: " + ec.message());
  const std::string probe = (fs::path(dir) / ".write-test").string();
  std::ofstream f(probe);
  if (!f || !(f << "ok") || !f.flush()) throw IoError(dir + ": results folder is not writable");
  f.close();
  fs::remove(probe, ec);
}

std::string duration(double s) {
  char b[64];
  if (s < 120) std::snprintf(b, sizeof b, "%.0f s", s);
  else if (s < 7200) std::snprintf(b, sizeof b, "%.1f min", s / 60);
  else std::snprintf(b, sizeof b, "%.1f h", s / 3600);
  return b;
}

void printSummary(const Runner& run) {
  std::printf("\n%-34s %8s %7s %6s %6s %7s %7s %6s %6s %9s\n", "stage", "p' kPa", "q kPa", "e", "Z", "Zm",
              "a_2D", "a_3D", "K0", "OCR");
  for (const StageSummary& s : run.summaries())
    std::printf("%-34.34s %8.1f %7.1f %6.3f %6.3f %7.3f %7.4f %6.4f %6.3f %9.3f\n", s.name.c_str(), s.end.p / 1e3,
                s.end.q / 1e3, s.end.voidRatio, s.end.Z, s.end.Zm, s.end.a2D, s.end.a3D, s.K0, s.ocr);
  std::printf("(a_2D: Rothenburg–Bathurst on vertical planes, a_3D = 5/2 (phi_zz - phi_xx); e from cell volume)\n");
  // where the time went, per pipeline stage: features a scene does not enable do not appear here
  const StageProfile& prof = run.simulation().profile();
  std::printf("profile (%ld steps, %ld neighbour rebuilds):", prof.steps, prof.rebuilds);
  for (int k = 0; k < static_cast<int>(Stage::Count); ++k)
    std::printf(" %s %.1f%%", stageName(static_cast<Stage>(k)), 100.0 * prof.seconds[k] / std::max(prof.total(), 1e-300));
  std::printf(" (the kick holds the next step's drift in %ld steps)\n", prof.fusedKicks);
  if (!run.samples().empty()) {
    double maxI = 0, maxErr = 0, maxMargin = 0;
    for (const Sample& s : run.samples()) {
      maxI = std::max(maxI, s.inertialNumber);
      maxErr = std::max(maxErr, s.energyError);
      maxMargin = std::max(maxMargin, s.timeStepMargin);
    }
    std::printf("honesty: max inertial number %.2g, max energy-balance error %.2g, max dt / critical step %.2g, "
                "final unbalanced force ratio %.2g, dt changes %ld\n",
                maxI, maxErr, maxMargin, run.samples().back().unbalanced, run.timeStepChanges());
  }
  if (!run.cycles().empty()) {
    const CycleRecord& f = run.cycles().front();
    const CycleRecord& l = run.cycles().back();
    std::printf("cycles: %zu  G_sec first %.1f MPa last %.1f MPa  damping first %.3f last %.3f  failure cycle %d\n",
                run.cycles().size(), f.Gsec / 1e6, l.Gsec / 1e6, f.damping, l.damping, run.failureCycle());
  }
}

}  // namespace

int runHeadless(int argc, char** argv) {
  std::string scenePath, restart, outDir, exportCsv, exportLammps;
  bool overwrite = false, quiet = false, outGiven = false;
  int threads = -1;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto next = [&](const char* what) -> std::string {
      if (k + 1 >= argc) {
        std::fprintf(stderr, "fabriclab-run: %s needs a value\n", what);
        std::exit(2);
      }
      return argv[++k];
    };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "--schema-doc") {
      const std::string doc = sceneReferenceMarkdown();
      if (k + 1 < argc) {
        std::ofstream(argv[k + 1]) << doc;
      } else {
        std::fputs(doc.c_str(), stdout);
      }
      return 0;
    } else if (a == "--out") {
      outDir = next("--out");
      outGiven = true;
    } else if (a == "--overwrite") {
      overwrite = true;
    } else if (a == "--quiet") {
      quiet = true;
    } else if (a == "--threads") {
      threads = std::atoi(next("--threads").c_str());
    } else if (a == "--restart") {
      restart = next("--restart");
    } else if (a == "--export-csv") {
      exportCsv = next("--export-csv");
    } else if (a == "--export-lammps") {
      exportLammps = next("--export-lammps");
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "fabriclab-run: unknown option %s\n", a.c_str());
      usage(stderr);
      return 2;
    } else {
      scenePath = a;
    }
  }
  if (scenePath.empty() && restart.empty()) {
    usage(stderr);
    return 2;
  }
  try {
    std::unique_ptr<Runner> run;
    if (!restart.empty()) {
      run = std::make_unique<Runner>(Runner::fromCheckpoint(restart));
    } else {
      Scene scene = loadScene(scenePath);
      if (threads > 0) scene.numerics.threads = threads;
      if (outGiven) scene.output.directory = outDir;
      if (!scene.output.directory.empty())
        prepareOutputDirectory(scene.output.directory, overwrite ? ExistingResults::Replace : ExistingResults::Refuse);
      run = std::make_unique<Runner>(std::move(scene));
    }
    const Scene& scene = run->scene();
    std::unique_ptr<RunOutputs> outputs;
    if (!scene.output.directory.empty()) {
      if (!restart.empty()) prepareOutputDirectory(scene.output.directory, ExistingResults::Keep);
      outputs = std::make_unique<RunOutputs>(scene.output.directory, scene);
      run->addObserver(outputs.get());
    }
    WarningPrinter warnings;
    run->addObserver(&warnings);
    const Simulation& sim = run->simulation();
    std::printf("FabricLab: scene '%s', %zu particles, %d stages, %d threads, dt %.3g s (%.2f of Rayleigh), "
                "density scale %g\n",
                scene.name.c_str(), sim.particles().size(), run->stageCount(), sim.numerics().threads,
                sim.timeStep(), sim.timeStep() / sim.rayleighStep(), sim.numerics().densityScale);
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    const auto t0 = std::chrono::steady_clock::now();
    const long firstStep = sim.stepCount();  // > 0 when the run continues a checkpoint
    long lastSteps = firstStep;
    auto lastReport = t0;
    double rate = 0;
    while (!run->finished()) {
      run->advance(500);
      if (g_signal.load()) {
        std::fprintf(stderr, "\nfabriclab-run: signal %d, stopping", g_signal.load());
        if (!scene.output.directory.empty()) {
          const std::string ck = run->checkpointPath("interrupted");
          run->writeCheckpoint(ck);
          std::fprintf(stderr, "; checkpoint %s (continue with --restart)", ck.c_str());
        }
        std::fprintf(stderr, "\n");
        return 130;
      }
      const auto now = std::chrono::steady_clock::now();
      const double dt = std::chrono::duration<double>(now - lastReport).count();
      if (!quiet && (dt > 1.0 || run->finished())) {
        rate = (sim.stepCount() - lastSteps) / std::max(dt, 1e-9);
        lastSteps = sim.stepCount();
        lastReport = now;
        const StageSpec* st = run->currentStage();
        const double prog = run->stageProgress();
        const double elapsed = std::chrono::duration<double>(now - t0).count();
        const StressMeasures s = stressMeasures(sim.contactStress());
        std::string eta = "?";
        if (st && (st->type == StageType::Cyclic || st->type == StageType::Triaxial) && prog > 0.01)
          eta = duration(elapsed * (1 - prog) / prog);  // rough: from this stage's progress
        std::fprintf(stderr, "\r[%d/%d] %-24.24s cycle %3d step %9ld t %.4g s  p' %8.1f kPa q %7.1f kPa  %5.1f%%  %.2e p-steps/s  ETA %s   ",
                     std::min(run->stageIndex() + 1, run->stageCount()), run->stageCount(),
                     st ? st->name.c_str() : "done", run->currentCycle(), sim.stepCount(), sim.time(), s.p / 1e3,
                     s.q / 1e3, 100 * prog, rate * sim.particles().size(), eta.c_str());
      }
    }
    if (!quiet) std::fprintf(stderr, "\n");
    printSummary(*run);
    if (!exportCsv.empty()) writePackingCsv(exportCsv, sim.particles(), sim.cell());
    if (!exportLammps.empty()) writeLammpsData(exportLammps, sim.particles(), sim.cell(), sim.materials());
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("wall time %s, %ld steps, %.3g particle-steps/s\n", duration(wall).c_str(), sim.stepCount() - firstStep,
                double(sim.stepCount() - firstStep) * double(sim.particles().size()) / std::max(wall, 1e-9));
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "fabriclab-run: input error: %s\n", e.what());
    return 2;
  } catch (const InstabilityError& e) {
    std::fprintf(stderr, "\nfabriclab-run: stopped: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fabriclab-run: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace fl::app
