// fabriclab-accuracy: the studies of issue 7 — accuracy against cost of the cyclic test (default), the
// full-size stability suite (--stability) and the profile of optional features (--profile). Each writes a
// Markdown report with measured numbers; the study logic lives in app/*_study.cpp (core only), this file
// only parses options, draws the plots (fl_charts, when built with the GUI) and writes files.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/accuracy_study.hpp"
#include "app/profile_study.hpp"
#include "app/stability_study.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"

#ifdef FL_WITH_CHARTS
#include "ui/chart_render.hpp"
#endif

namespace fs = std::filesystem;

namespace {

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: fabriclab-accuracy [options]                accuracy against cost of the cyclic test\n"
               "       fabriclab-accuracy --stability [options]    the stability suite at full size\n"
               "       fabriclab-accuracy --profile [options]      cost of optional features, per pipeline stage\n"
               "options:\n"
               "  --out DIR        working folder: specimens, results.json, accuracy.csv (default out/accuracy,\n"
               "                   out/stability, out/profile)\n"
               "  --report FILE    Markdown report (default DIR/<study>.md); the accuracy plots go to a folder\n"
               "                   named after the report (docs/accuracy-vs-cost.md -> docs/accuracy-vs-cost/)\n"
               "  --jobs N         runs in parallel (threads, one per run; results do not depend on it)\n"
               "  --quick          accuracy: tiny ladder, 400 spheres, 1 cycle (CI)\n"
               "  --particles N    base particle count (accuracy: 2000; stability: 4000; profile: 2000)\n"
               "  --cycles N       accuracy: cycles per run (default 2)\n"
               "  --from FILE      accuracy: re-write CSV, plots and report from a previous results.json\n");
}

void writeText(const std::string& path, const std::string& text) {
  const fs::path p(path);
  if (p.has_parent_path()) fs::create_directories(p.parent_path());
  fl::writeFileAtomically(path, text);
}

void say(const std::string& m) {
  std::fprintf(stderr, "%s\n", m.c_str());
  std::fflush(stderr);
}

// Draws the plots into imageDir; returns the files drawn.
std::vector<std::string> drawPlots(const std::vector<fl::accuracy::PlotSpec>& specs, const std::string& imageDir) {
  std::vector<std::string> drawn;
#ifdef FL_WITH_CHARTS
  fs::create_directories(imageDir);
  fl::charts::ensureApplication();
  for (const auto& s : specs) {
    fl::charts::Chart c;
    c.title = s.title;
    c.xLabel = s.xLabel;
    c.yLabel = s.yLabel;
    c.logX = s.logX;
    c.logY = s.logY;
    for (const auto& x : s.series) c.series.push_back({x.name, x.x, x.y, x.markers});
    fl::charts::renderPng(c, (fs::path(imageDir) / s.file).string());
    drawn.push_back(s.file);
  }
#else
  (void)specs;
  (void)imageDir;
  say("note: built without the Qt chart library (fl_charts): no plots drawn");
#endif
  return drawn;
}

}  // namespace

int main(int argc, char** argv) {
  std::string mode = "accuracy", outDir, report, from;
  int jobs = 1, particles = 0, cycles = 0;
  bool quick = false;
  std::string command = "fabriclab-accuracy";
  for (int k = 1; k < argc; ++k) command += std::string(" ") + argv[k];
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto next = [&](const char* what) -> std::string {
      if (k + 1 >= argc) {
        std::fprintf(stderr, "fabriclab-accuracy: %s needs a value\n", what);
        std::exit(2);
      }
      return argv[++k];
    };
    auto positive = [&](const char* what) {
      const std::string v = next(what);
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (!end || *end || n < 1 || n > 10000000) {
        std::fprintf(stderr, "fabriclab-accuracy: %s must be a positive integer, got '%s'\n", what, v.c_str());
        std::exit(2);
      }
      return static_cast<int>(n);
    };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "--stability") {
      mode = "stability";
    } else if (a == "--profile") {
      mode = "profile";
    } else if (a == "--quick") {
      quick = true;
    } else if (a == "--out") {
      outDir = next("--out");
    } else if (a == "--report") {
      report = next("--report");
    } else if (a == "--from") {
      from = next("--from");
    } else if (a == "--jobs") {
      jobs = positive("--jobs");
    } else if (a == "--particles") {
      particles = positive("--particles");
    } else if (a == "--cycles") {
      cycles = positive("--cycles");
    } else {
      std::fprintf(stderr, "fabriclab-accuracy: unknown option %s\n", a.c_str());
      usage(stderr);
      return 2;
    }
  }
  if (outDir.empty()) outDir = "out/" + mode;
  try {
    fs::create_directories(outDir);
    if (mode == "stability") {
      fl::stability::StudyOptions o;
      if (particles) o.count = particles;
      o.jobs = jobs;
      o.workDir = outDir;
      const auto r = fl::stability::runStudy(o, say);
      if (report.empty()) report = (fs::path(outDir) / "stability.md").string();
      writeText(report, fl::stability::reportMarkdown(r, command));
      std::printf("stability: %zu cases, %.0f s wall, %.0f s CPU; report %s\n", r.cases.size(), r.wallSeconds, r.cpuSeconds,
                  report.c_str());
      return 0;
    }
    if (mode == "profile") {
      fl::profile::Options o;
      if (particles) o.particles = particles;
      o.workDir = outDir;
      const auto r = fl::profile::run(o, say);
      if (report.empty()) report = (fs::path(outDir) / "profile.md").string();
      writeText(report, fl::profile::reportMarkdown(r, command));
      std::printf("profile: %zu variants in %.0f s; report %s\n", r.variants.size(), r.totalSeconds, report.c_str());
      return 0;
    }
    // accuracy against cost
    fl::accuracy::StudyResult r;
    if (!from.empty()) {
      std::ifstream in(from);
      if (!in) throw fl::IoError(from + ": cannot open");
      r = fl::accuracy::resultFromJson(nlohmann::json::parse(in));
    } else {
      fl::accuracy::StudyConfig c = quick ? fl::accuracy::quickConfig() : fl::accuracy::fullConfig();
      if (particles) {
        for (auto& l : c.ladders)  // the base count is a rung of the particle-count ladder
          if (l.factor == fl::accuracy::Factor::ParticleCount)
            for (double& v : l.values)
              if (v == c.base.particles) v = particles;
        c.base.particles = particles;
      }
      if (cycles) c.cycles = cycles;
      c.jobs = jobs;
      r = fl::accuracy::runStudy(c, outDir, say);
      r.command = command;
      writeText((fs::path(outDir) / "results.json").string(), fl::accuracy::resultJson(r).dump(1));
    }
    writeText((fs::path(outDir) / "accuracy.csv").string(), fl::accuracy::csvText(r));
    if (report.empty()) report = (fs::path(outDir) / "accuracy-vs-cost.md").string();
    const fs::path rp(report);
    const std::string imageName = rp.stem().string();
    const std::string imageDir = (rp.parent_path() / imageName).string();
    const auto drawn = drawPlots(fl::accuracy::plots(r), imageDir);
    // the table ships with the report
    writeText((fs::path(imageDir) / "accuracy.csv").string(), fl::accuracy::csvText(r));
    writeText(report, fl::accuracy::reportMarkdown(r, imageName, drawn, command));
    std::printf("accuracy: %zu runs, %.0f s wall, %.0f s CPU; %s, %s, %zu plots in %s\n", r.runs.size(), r.wallSeconds,
                r.cpuSeconds, (fs::path(outDir) / "accuracy.csv").string().c_str(), report.c_str(), drawn.size(),
                imageDir.c_str());
    return 0;
  } catch (const fl::InputError& e) {
    std::fprintf(stderr, "fabriclab-accuracy: input error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fabriclab-accuracy: error: %s\n", e.what());
    return 1;
  }
}
