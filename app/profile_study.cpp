#include "profile_study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/runner.hpp"
#include "core/scene.hpp"
#include "core/simulation.hpp"

namespace fl::profile {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {
std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

// The edits of each variant, in the order of variants().
void applyVariant(std::size_t k, json& j, const std::string& outDir) {
  switch (k) {
    case 0: break;
    case 1: j["numerics"]["track_energy"] = true; break;
    case 2: j["numerics"]["local_damping"] = 0.05; break;
    case 3: j["numerics"]["restitution"] = 0.5; break;
    case 4:
      j["numerics"]["track_energy"] = true;
      j["numerics"]["local_damping"] = 0.05;
      j["numerics"]["restitution"] = 0.5;
      break;
    case 5: j["stages"][0]["samples_per_cycle"] = 400; break;
    case 6: j["output"]["check_interval"] = 10; break;
    case 7:
      j["output"]["directory"] = outDir;
      j["output"]["vtk_interval"] = 500;
      break;
    case 8:
      j["output"]["directory"] = outDir;
      j["output"]["checkpoint_interval"] = 1000;
      break;
    case 9: j["numerics"]["tangential_model"] = "mindlin_deresiewicz"; break;
    default: throw Error("no such profile variant");
  }
}

struct Count final : RunObserver {
  long samples = 0;
  void onSample(const Sample&) override { ++samples; }
};

long countFiles(const fs::path& d) {
  long n = 0;
  std::error_code ec;
  if (!fs::exists(d, ec)) return 0;
  for (const auto& e : fs::recursive_directory_iterator(d, ec))
    if (e.is_regular_file()) ++n;
  return n;
}
}  // namespace

std::vector<Variant> variants() {
  std::vector<Variant> v = {
      {"baseline: everything optional off", "track_energy false, local_damping 0, restitution 1, no output folder, "
                                            "samples_per_cycle 8, check_interval 100"},
      {"energy tracking on", "numerics.track_energy = true"},
      {"local damping on", "numerics.local_damping = 0.05"},
      {"contact damping on", "numerics.restitution = 0.5"},
      {"all three on", "track_energy true, local_damping 0.05, restitution 0.5"},
      {"dense measurements", "stages[].samples_per_cycle = 400 (a sample every ~22 steps instead of ~1100)"},
      {"frequent checks", "output.check_interval = 10 (guards and completion checks 10x as often)"},
      {"ParaView snapshots", "output.directory set, output.vtk_interval = 500"},
      {"periodic checkpoints", "output.directory set, output.checkpoint_interval = 1000"},
  };
  // the optional micro-slip tangential law, when this build's schema offers it
  for (const SchemaField& f : sceneSchema())
    if (f.section == "numerics" && f.key == "tangential_model" &&
        std::find(f.choices.begin(), f.choices.end(), "mindlin_deresiewicz") != f.choices.end())
      v.push_back({"Mindlin–Deresiewicz tangential law", "numerics.tangential_model = mindlin_deresiewicz"});
  return v;
}

Result run(const Options& options, const std::function<void(const std::string&)>& log) {
  Result res;
  res.options = options;
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path dir = options.workDir;
  fs::create_directories(dir);
  // the specimen: paper glass at 318 kPa (fast preparation; not timed)
  json prep = {
      {"name", "profile specimen"},
      {"specimen", {{"source", "gas"}, {"count", options.particles}, {"solid_fraction", 0.3}, {"seed", 1}}},
      {"numerics", {{"time_step_factor", 0.3}, {"local_damping", 0.1}, {"density_scale", 100}, {"threads", 1}}},
      {"servo", {{"max_strain_rate", 10}, {"max_inertial_number", 1e-2}, {"unbalanced_tolerance", 5e-3}}},
      {"stages", json::array({{{"type", "isotropic_compression"}, {"name", "deposition"}, {"pressure", 50e3},
                               {"friction", 0.02}, {"friction_after", 0.235}},
                              {{"type", "isotropic_compression"}, {"name", "consolidation"}, {"pressure", 318e3}}})},
      {"output", {{"directory", (dir / "specimen").string()}, {"sample_interval", 100000}}}};
  if (log) log("preparing the " + std::to_string(options.particles) + "-sphere specimen ...");
  std::string checkpoint;
  {
    Runner r(parseScene(prep, "profile-specimen.json"));
    while (r.advance(10000)) {
    }
    checkpoint = r.summaries().back().checkpoint;
  }
  const json base = {
      {"name", "profile run"},
      {"specimen", {{"source", "checkpoint"}, {"path", checkpoint}}},
      {"numerics", {{"time_step_factor", 0.25}, {"local_damping", 0.0}, {"restitution", 1.0}, {"density_scale", 1},
                    {"threads", 1}, {"track_energy", false}}},
      {"stages", json::array({{{"type", "cyclic"}, {"name", "cycles"}, {"drainage", "undrained"}, {"amplitude", 2.3e-4},
                               {"cycles", 100}, {"inertial_number", 1e-4}, {"samples_per_cycle", 8}}})},
      {"output", {{"sample_interval", 1000000}, {"check_interval", 100}, {"checkpoint_at_stage_end", false}}}};

  const std::vector<Variant> vs = variants();
  std::vector<std::vector<Measured>> reps(vs.size());
  // repeats interleaved (variant 0..n, then again) so that a change of machine load hits every variant alike
  for (int rep = 0; rep < options.repeats; ++rep) {
    for (std::size_t k = 0; k < vs.size(); ++k) {
      const fs::path out = dir / ("variant-" + std::to_string(k));
      fs::remove_all(out);
      json j = base;
      applyVariant(k, j, out.string());
      if (j["output"].contains("directory")) fs::create_directories(out);
      Runner r(parseScene(j, "profile-run.json"));
      Count count;
      r.addObserver(&count);
      const StageProfile p0 = r.simulation().profile();
      const auto w0 = std::chrono::steady_clock::now();
      r.advance(options.steps);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      const StageProfile& p1 = r.simulation().profile();
      Measured m;
      m.variant = vs[k];
      double simTotal = 0;
      for (int s = 0; s < 5; ++s) {
        m.stageSeconds[s] = p1.seconds[s] - p0.seconds[s];
        simTotal += m.stageSeconds[s];
      }
      m.wallSeconds = wall;
      m.runnerSeconds = std::max(0.0, wall - simTotal);
      m.samples = count.samples;
      m.files = countFiles(out);
      reps[k].push_back(m);
      if (log)
        log("  [" + std::to_string(rep + 1) + "/" + std::to_string(options.repeats) + "] " + vs[k].name + ": " +
            fmt("%.3f s", wall));
      fs::remove_all(out);
    }
  }
  for (std::size_t k = 0; k < vs.size(); ++k) {
    Measured best = reps[k].front();
    double wmax = 0;
    for (const Measured& m : reps[k]) {
      for (int s = 0; s < 5; ++s) best.stageSeconds[s] = std::min(best.stageSeconds[s], m.stageSeconds[s]);
      best.runnerSeconds = std::min(best.runnerSeconds, m.runnerSeconds);
      best.wallSeconds = std::min(best.wallSeconds, m.wallSeconds);
      wmax = std::max(wmax, m.wallSeconds);
    }
    best.spread = (wmax - best.wallSeconds) / best.wallSeconds;
    res.variants.push_back(best);
  }
  res.totalSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream m;
  m << std::thread::hardware_concurrency() << " cores";
  std::ifstream la("/proc/loadavg");
  double l1 = 0, l5 = 0, l15 = 0;
  if (la >> l1 >> l5 >> l15) m << ", load average " << l1 << " / " << l5 << " / " << l15 << " (1 / 5 / 15 min, at the end)";
  res.machine = m.str();
  return res;
}

std::string reportMarkdown(const Result& r, const std::string& command) {
  std::ostringstream o;
  const Options& op = r.options;
  o << "# Profile: what a scene does not ask for costs nothing (issue 7, part 5)\n\n";
  o << "Generated by `" << command << "` in " << fmt("%.0f s", r.totalSeconds)
    << "; every time below is measured by that run. Machine: " << r.machine << ".\n\n";
  o << "## Measurement\n\n";
  o << "One specimen of " << op.particles
    << " glass beads at p′ = 318 kPa; each variant restores it and runs " << op.steps
    << " steps of the undrained cyclic test (ε_a = ±0.023 %, inertial number 1e-4, time_step_factor 0.25, one "
       "thread). Times come from the simulation's per-stage profile (`Simulation::profile()`: drift, neighbours, "
       "contacts, kick, control, as printed by `fabriclab-run`), and the runner's own time is the wall time minus the "
       "profile total (measurements, guards, completion checks, files). Each variant ran "
    << op.repeats
    << " times, interleaved with the others; the table shows the least time per column (the most stable statistic "
       "when other processes share the cores) and the spread of the wall time over the repeats.\n\n";
  const Measured& b = r.variants.front();
  o << "| variant | scene fields changed | drift | neighbours | contacts | kick | control | runner | wall | vs baseline "
       "| spread | samples | files |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Measured& m : r.variants) {
    o << "| " << m.variant.name << " | " << m.variant.switches << " |";
    for (int s = 0; s < 5; ++s) o << " " << fmt("%.3f", m.stageSeconds[s]) << " |";
    o << " " << fmt("%.3f", m.runnerSeconds) << " | " << fmt("%.3f s", m.wallSeconds) << " | "
      << (&m == &b ? std::string("—") : fmt("%+.1f %%", 100.0 * (m.wallSeconds / b.wallSeconds - 1.0))) << " | "
      << fmt("%.0f %%", 100 * m.spread) << " | " << m.samples << " | " << m.files << " |\n";
  }
  o << "\nAll times in seconds for the " << op.steps << " timed steps. “vs baseline” compares the least wall times.\n\n";

  // per-stage deltas of the numerical switches
  auto delta = [&](std::size_t k, int s) {
    return r.variants.size() > k ? r.variants[k].stageSeconds[s] - b.stageSeconds[s] : 0.0;
  };
  o << "## Reading the table\n\n";
  if (r.variants.size() >= 9) {
    const int kDrift = 0, kContacts = 2, kKick = 3;
    auto d = [&](double x) { return std::abs(x) < 0.0005 ? std::string("±0.000 s") : fmt("%+.3f s", x); };
    auto pctOf = [&](double x, double base) { return base > 0 ? fmt("%+.0f %%", 100.0 * x / base) : std::string("—"); };
    o << "Changes against the baseline, per stage (least of the repeats; differences within the spread column are "
         "the noise of the shared machine):\n\n";
    o << "- **Energy tracking**: contact pass " << d(delta(1, kContacts)) << " (" << pctOf(delta(1, kContacts), b.stageSeconds[kContacts])
      << "), drift " << d(delta(1, kDrift))
      << " (boundary work). Switched off, the contact pass runs the instantiation without the energy sums.\n";
    o << "- **Local damping**: kick " << d(delta(2, kKick)) << " (" << pctOf(delta(2, kKick), b.stageSeconds[kKick]) << "), drift "
      << d(delta(2, kDrift)) << " (" << pctOf(delta(2, kDrift), b.stageSeconds[kDrift])
      << "). At α = 0 the kick runs the instantiation without it and the drift skips it.\n";
    o << "- **Contact damping**: contact pass " << d(delta(3, kContacts)) << " (" << pctOf(delta(3, kContacts), b.stageSeconds[kContacts])
      << "). At e = 1 the dashpot is not compiled into the contact pass."
      << (delta(3, kContacts) < 0 ? " (The damped instantiation does strictly more arithmetic per contact, so a lower "
                                    "time comes from the damped run's different trajectory (other contact states), "
                                    "not from the code.)"
                                  : "")
      << "\n";
    o << "- **Measurements** are on their own schedule: " << r.variants[5].samples << " samples instead of " << b.samples
      << " cost " << d(r.variants[5].runnerSeconds - b.runnerSeconds)
      << " of runner time; the per-stage times of the step do not depend on them. Checks every 10 steps instead of 100: "
      << d(r.variants[6].runnerSeconds - b.runnerSeconds) << " of runner time.\n";
    o << "- **Files**: ParaView snapshots every 500 steps (" << r.variants[7].files << " files) cost "
      << d(r.variants[7].runnerSeconds - b.runnerSeconds) << " of runner time, checkpoints every 1000 steps ("
      << r.variants[8].files << (r.variants[8].files == 1 ? " file, rewritten" : " files") << ") "
      << d(r.variants[8].runnerSeconds - b.runnerSeconds)
      << ". Without an output folder nothing is formatted or written.\n";
    if (r.variants.size() >= 10)
      o << "- **Mindlin–Deresiewicz tangential law** (opt-in): contact pass " << d(delta(9, kContacts)) << " ("
        << pctOf(delta(9, kContacts), b.stageSeconds[kContacts])
        << "); with the default law its history is neither allocated nor touched.\n";
    o << "\n";
  }

  o << "## How the engine gets there\n\n";
  o << "- **One instantiation of the contact pass per feature combination.** `Simulation::computeContacts()` picks, "
       "once per step and not per pair, the instantiation of the templated `contactPass<…>()` for the combination of "
       "`numerics.track_energy`, contact damping (`numerics.restitution < 1`), cell deformation (velocity gradient "
       "L ≠ 0) and the tangential law (`numerics.tangential_model`). Inside the loop the optional terms are "
       "`if constexpr`: a disabled term is not a branch, it is absent from the machine code. Likewise "
       "`kickPass<kLocalDamping>()` for `numerics.local_damping > 0`. (The drift applies the damping of its half "
       "kick behind one run-time test of α per particle.)\n";
  o << "- **Measurements run on their own schedule in the runner**, never inside the step: time-series samples "
       "every `output.sample_interval` steps (or `samples_per_cycle` per cycle in cyclic stages), guards and completion "
       "checks every `output.check_interval` steps (the unbalanced force is O(N)), ParaView and checkpoint files "
       "only with an output folder and a non-zero interval. The step computes only the stress (summed in the force "
       "pass) and O(1) diagnostics.\n";
  o << "- **Nothing is measured by re-running the force law**: fabric, coordination and stresses read the stored "
       "contact data.\n\n";

  o << "## Every switch that turns something off\n\n";
  o << "| scene field | off when | what is skipped |\n|---|---|---|\n";
  o << "| `numerics.track_energy` | false | elastic energy, friction/damping work and boundary work sums (contact pass "
       "and drift); the energy guard and the energy columns (then 0) |\n";
  o << "| `numerics.local_damping` | 0 | Cundall damping in the kick (separate instantiation) and the drift's half kick |\n";
  o << "| `numerics.restitution` | 1 | viscous contact damping (separate instantiation of the contact pass) |\n";
  o << "| (cell velocity gradient) | L = 0 (hold, static stages) | the affine L·l term of the relative velocity and the "
       "boundary work (separate instantiation) |\n";
  o << "| `numerics.tangential_model` | mindlin_no_slip (default) | the Mindlin–Deresiewicz micro-slip history: not "
       "allocated, not updated (separate instantiation) |\n";
  o << "| `numerics.density_scale` | 1 | nothing to skip: scaling only changes masses at set-up |\n";
  o << "| `output.directory` | empty | every file: time series, cycles, stage summaries, checkpoints, snapshots |\n";
  o << "| `output.vtk_interval` | 0 | ParaView snapshots |\n";
  o << "| `output.checkpoint_interval` | 0 | periodic checkpoints |\n";
  o << "| `output.checkpoint_at_stage_end` | false | the checkpoint after each stage |\n";
  o << "| `output.sample_interval`, `stages[].samples_per_cycle` | large / small | time-series samples (stress, "
       "fabric, Z, energies: O(N + C) each) |\n";
  o << "| `output.check_interval` | large | completion checks, the adaptive time step and the energy and inertial-number "
       "guards (O(N) each) |\n";
  o << "| `guards.adaptive_time_step` | false | the time-step update at each check (O(1)) |\n";
  o << "| `numerics.threads` | 1 | OpenMP parallel regions still run, on one thread (results are identical for any "
       "count) |\n";
  return o.str();
}

}  // namespace fl::profile
