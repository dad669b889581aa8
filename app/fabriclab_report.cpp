// fabriclab-report: the paper report of a study folder (see app/report_paper.hpp).
//   fabriclab-report [--study out/paper] [--out docs/paper-report] [--notes FILE]
// Writes <out>/README.md and <out>/fig-*.png. --notes defaults to docs/paper-report-notes.md when that file
// exists. Exit codes: 0 written, 1 error (I/O, rendering), 2 bad input (usage, garbled result files).
// Needs no display: charts render on Qt's "offscreen" platform. No VTK.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>

#include "app/report_paper.hpp"
#include "core/errors.hpp"
#include "ui/chart_render.hpp"

namespace {

void usage(std::FILE* to) {
  std::fprintf(to,
               "usage: fabriclab-report [--study DIR] [--out DIR] [--notes FILE]\n"
               "  --study DIR   study folder with one results folder per paper scene (default out/paper)\n"
               "  --out DIR     report folder: README.md and fig-*.png (default docs/paper-report)\n"
               "  --notes FILE  Markdown included verbatim as the discussion\n"
               "                (default docs/paper-report-notes.md if it exists)\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string study = "out/paper", out = "docs/paper-report", notes;
  bool notesGiven = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](std::string& into) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "fabriclab-report: %s needs a value\n", a.c_str());
        usage(stderr);
        std::exit(2);
      }
      into = argv[++i];
    };
    if (a == "--study") value(study);
    else if (a == "--out") value(out);
    else if (a == "--notes") {
      value(notes);
      notesGiven = true;
    } else if (a == "-h" || a == "--help") {
      usage(stdout);
      return 0;
    } else {
      std::fprintf(stderr, "fabriclab-report: unknown argument '%s'\n", a.c_str());
      usage(stderr);
      return 2;
    }
  }
  if (!notesGiven && std::filesystem::exists("docs/paper-report-notes.md")) notes = "docs/paper-report-notes.md";

  try {
    fl::charts::ensureApplication();
    const fl::report::ReportSummary s = fl::report::writePaperReport(study, out, notes);
    std::printf("report: %s, %zu figures\n", s.readme.c_str(), s.figures.size());
    if (!notes.empty()) std::printf("discussion: %s\n", notes.c_str());
    for (const std::string& f : s.notRun) std::printf("not run: %s\n", f.c_str());
    for (const std::string& f : s.incomplete) std::printf("incomplete: %s\n", f.c_str());
    return 0;
  } catch (const fl::InputError& e) {
    std::fprintf(stderr, "fabriclab-report: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fabriclab-report: %s\n", e.what());
    return 1;
  }
}
