#include "stability_study.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/errors.hpp"
#include "core/runner.hpp"
#include "core/scene.hpp"

namespace fl::stability {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {
double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
std::string secs(double s) { return s < 100 ? fmt("%.1f s", s) : fmt("%.0f s", s); }
std::string slug(const std::string& s) {
  std::string o;
  for (char c : s) o += std::isalnum(static_cast<unsigned char>(c)) ? static_cast<char>(std::tolower(c)) : '-';
  return o;
}
std::string escapePipes(std::string s) {
  for (std::size_t k = 0; (k = s.find('|', k)) != std::string::npos; k += 2) s.replace(k, 1, "\\|");
  for (char& c : s)
    if (c == '\n') c = ' ';
  return s;
}
}  // namespace

void classify(CaseResult& c) {
  const Outcome& o = c.outcome;
  if (!c.otherError.empty()) {
    c.verdict = "FAILED: " + c.otherError;
    c.contractHolds = c.asExpected = false;
    return;
  }
  if (o.completed) {
    std::vector<std::string> why;
    if (!o.finite) why.push_back("non-finite sample");
    if (!(o.maxOverlap < c.overlapLimit)) why.push_back("overlap " + fmt("%.3g", o.maxOverlap) + " >= " + fmt("%.3g", c.overlapLimit));
    if (!(o.maxEnergyError < kEnergyBound)) why.push_back("energy error " + fmt("%.3g", o.maxEnergyError) + " >= " + fmt("%.3g", kEnergyBound));
    if (why.empty()) {
      c.verdict = "ran bounded";
      c.contractHolds = c.asExpected = true;
    } else {
      std::string w;
      for (const auto& s : why) w += (w.empty() ? "" : ", ") + s;
      c.verdict = "FAILED: completed unbounded (" + w + ")";
      c.contractHolds = c.asExpected = false;
    }
    return;
  }
  const bool diagnostic = o.error.find("To fix:") != std::string::npos;
  c.contractHolds = diagnostic;
  c.asExpected = diagnostic && c.mayStop;
  if (!diagnostic) c.verdict = "FAILED: stopped without a fix in the message";
  else if (c.mayStop) c.verdict = "stopped with a diagnostic";
  else c.verdict = "stopped with a diagnostic (the reduced test expects it to complete)";
}

namespace {

Runner runAll(const json& j) {
  Runner r(parseScene(j, "stability-specimen.json"));
  while (r.advance(5000)) {
  }
  return r;
}

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

}  // namespace

StudyResult runStudy(const StudyOptions& options, const std::function<void(const std::string&)>& log) {
  StudyResult res;
  res.options = options;
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();
  std::mutex logMutex;
  auto say = [&](const std::string& m) {
    std::lock_guard<std::mutex> lock(logMutex);
    if (log) log(m);
  };
  const fs::path dir = options.workDir;
  fs::create_directories(dir);

  // 1. the two specimens at 318 kPa
  struct Spec {
    std::string name;
    double muC;
    std::string checkpoint;
  };
  std::vector<Spec> specs = {{"standard (mu_c 0.1)", 0.1, ""}, {"jammed dense (mu_c 0)", 0.0, ""}};
  res.specimens.resize(specs.size());
  std::vector<std::string> errors(specs.size());
  parallelFor(static_cast<int>(specs.size()), options.jobs, [&](int k) {
    say("preparing the " + specs[k].name + " specimen of " + std::to_string(options.count) + " spheres ...");
    const auto s0 = std::chrono::steady_clock::now();
    try {
      json prep = baseScene(options.count);
      prep["output"]["directory"] = (dir / ("specimen-" + slug(specs[k].name))).string();
      prep["stages"] = preparationStages(specs[k].muC);
      Runner r = runAll(prep);
      specs[k].checkpoint = r.summaries().back().checkpoint;
      const Sample& e = r.summaries().back().end;
      res.specimens[k] = {specs[k].name, specs[k].muC, e.p, e.voidRatio, e.Z,
                          std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count()};
      say("  " + specs[k].name + ": e " + fmt("%.3f", e.voidRatio) + ", Z " + fmt("%.2f", e.Z) + " (" +
          secs(res.specimens[k].seconds) + ")");
    } catch (const std::exception& e) {
      errors[k] = e.what();
    }
  });
  for (std::size_t k = 0; k < specs.size(); ++k)
    if (!errors[k].empty()) throw Error("preparing the " + specs[k].name + " specimen failed: " + errors[k]);

  // 2. every branch case from both specimens, then the gas cases
  struct Task {
    CaseResult c;
    json scene;
  };
  std::vector<Task> tasks;
  for (const Spec& sp : specs)
    for (const Case& c : branchCases()) {
      Task t;
      t.c.specimen = sp.name;
      t.c.name = c.name;
      t.c.mayStop = c.mayStop;
      t.c.overlapLimit = c.overlapLimit;
      t.scene = baseScene(options.count);
      t.scene["specimen"] = {{"source", "checkpoint"}, {"path", sp.checkpoint}};
      t.scene["output"]["directory"] = (dir / ("case-" + slug(sp.name) + "-" + slug(c.name))).string();
      t.scene["output"]["checkpoint_at_stage_end"] = false;
      c.edit(t.scene);
      tasks.push_back(std::move(t));
    }
  {
    Task g;
    g.c.specimen = "gas";
    g.c.name = "loose gas, no damping (hold 3000 steps)";
    g.scene = looseGasScene(options.count);
    tasks.push_back(g);
    Task s;
    s.c.specimen = "gas";
    s.c.name = "10:1 size ratio to 100 kPa";
    s.scene = sizeRatioScene(options.count);
    s.scene["output"]["directory"] = (dir / "case-size-ratio").string();
    s.scene["output"]["checkpoint_at_stage_end"] = false;
    tasks.push_back(s);
  }
  std::atomic<int> done{0};
  parallelFor(static_cast<int>(tasks.size()), options.jobs, [&](int k) {
    Task& t = tasks[k];
    try {
      t.c.outcome = tryRun(t.scene, 1);  // probe the overlap every step
    } catch (const std::exception& e) {
      t.c.otherError = e.what();
    }
    classify(t.c);
    say("  [" + std::to_string(++done) + "/" + std::to_string(tasks.size()) + "] " + t.c.specimen + " / " + t.c.name + ": " +
        t.c.verdict + " (" + secs(t.c.outcome.wallSeconds) + ")");
  });
  for (Task& t : tasks) res.cases.push_back(std::move(t.c));
  res.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  res.cpuSeconds = processCpuSeconds() - cpu0;
  std::ostringstream m;
  m << std::thread::hardware_concurrency() << " cores";
  std::ifstream la("/proc/loadavg");
  double l1 = 0, l5 = 0, l15 = 0;
  if (la >> l1 >> l5 >> l15) m << ", load average " << l1 << " / " << l5 << " / " << l15 << " (1 / 5 / 15 min, at the end)";
  res.machine = m.str();
  return res;
}

std::string reportMarkdown(const StudyResult& r, const std::string& command) {
  std::ostringstream o;
  const int n = r.options.count;
  o << "# Numerical stability at full size (issue 7, part 3)\n\n";
  o << "Generated by `" << command << "`; every number is measured by that run.\n\n";
  o << "Whole study: **" << secs(r.wallSeconds) << " wall, " << secs(r.cpuSeconds) << " CPU** (" << r.options.jobs
    << " job" << (r.options.jobs > 1 ? "s" : "") << ", one thread per case). Machine: " << r.machine << ".\n\n";
  o << "## What is run\n\n";
  o << "The cases of the reduced CI suite (`tests/stability_test.cpp`, 400 spheres; shared definitions in "
       "`app/stability_cases.cpp`) at **"
    << n
    << " spheres**, with the suite's numerics: glass beads of the paper unless a case changes them, "
       "time_step_factor 0.3, local damping 0.1, density scale 100, one thread, adaptive time step on "
       "(dt ≤ 0.35 × the stiffness-based critical step 2√(m*/k)), guards at their defaults (stop at overlap > 5 % of "
       "the smaller radius or energy created > 25 % of the turnover). Every branch case starts from a specimen "
       "compressed to 318 kPa; there are two:\n\n";
  o << "| specimen | compression friction | p′ [kPa] | e | Z | preparation wall |\n|---|---|---|---|---|---|\n";
  for (const SpecimenState& s : r.specimens)
    o << "| " << s.name << " | " << fmt("%g", s.muC) << " | " << fmt("%.1f", s.p / 1e3) << " | " << fmt("%.3f", s.voidRatio)
      << " | " << fmt("%.2f", s.Z) << " | " << secs(s.seconds) << " |\n";
  o << "\nCases (each edits the scene): glass ×10 and ×100 stiffer (re-compressed to 318 kPa, one undrained cycle at "
       "1 /s); very soft G = 10 MPa at 50 kPa (expected to stop: overlaps beyond 5 % of r) and the same with "
       "guards.max_overlap_ratio raised to 0.15; 1 kPa; 10 MPa; μ = 0 and μ = 1; no local damping; strain rate 100 /s; "
       "a loose gas with no contacts and no damping (hold 3000 steps); a 10:1 size ratio compressed to 100 kPa from a "
       "gas.\n\n";
  o << "Contract: each case either **runs bounded** (finite, max overlap below the stated fraction of the radius, "
       "energy-balance error below "
    << fmt("%g %%", 100 * kEnergyBound)
    << ") or **stops with a diagnostic** (an InstabilityError naming the cause, a fix and a diagnostic checkpoint) — "
       "never a silent NaN.\n\n";

  int holds = 0, expected = 0;
  for (const CaseResult& c : r.cases) {
    holds += c.contractHolds;
    expected += c.asExpected;
  }
  o << "## Result\n\n";
  o << "**Contract holds in " << holds << " of " << r.cases.size() << " cases**; " << expected << " of " << r.cases.size()
    << " behave as the reduced test expects (complete unless marked “may stop”).\n\n";
  o << "| specimen | case | outcome | max overlap / r | energy-balance error | dt / Rayleigh (min–max) | max dt / critical "
       "| steps | dt changes | final p′ [kPa] | wall |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const CaseResult& c : r.cases) {
    const Outcome& x = c.outcome;
    o << "| " << c.specimen << " | " << c.name << (c.mayStop ? " (may stop)" : "") << " | " << escapePipes(c.verdict) << " | "
      << fmt("%.3g", x.maxOverlap) << " (limit " << fmt("%g", c.overlapLimit) << ") | " << fmt("%.2g", x.maxEnergyError)
      << " | " << fmt("%.3f", x.minDtOverRayleigh) << "–" << fmt("%.3f", x.maxDtOverRayleigh) << " | "
      << fmt("%.3f", x.maxDtOverCritical) << " | " << x.steps << " | " << x.timeStepChanges << " | "
      << fmt("%.1f", x.finalPressure / 1e3) << " | " << secs(x.wallSeconds) << " |\n";
  }
  o << "\nColumns: max overlap / r is the largest overlap over the smaller radius, probed every step (for a stopped "
       "case: at the stop); the energy-balance error is the largest over the samples, |balance drift| / max(boundary "
       "work, dissipation, stored energy); dt / Rayleigh is the time step used over the Rayleigh step of the case "
       "(with its density scaling and stiffness); dt / critical is against 2√(m*/k_max) of the stiffest contact "
       "(stable below 1, the guard keeps it ≤ 0.35).\n\n";
  bool anyStop = false;
  for (const CaseResult& c : r.cases) anyStop |= !c.outcome.completed;
  if (anyStop) {
    o << "## Diagnostics of the stopped cases\n\n";
    for (const CaseResult& c : r.cases) {
      if (c.outcome.completed) continue;
      std::string msg = c.otherError.empty() ? c.outcome.error : c.otherError;
      const std::size_t ck = msg.find(" Diagnostic checkpoint:");
      if (ck != std::string::npos) msg = msg.substr(0, ck) + " (a diagnostic checkpoint was written)";
      o << "- " << c.specimen << " / " << c.name << ": " << msg << "\n";
    }
    o << "\n";
  }
  return o.str();
}

}  // namespace fl::stability
