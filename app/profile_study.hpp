// What disabled features and unrequested measurements cost (issue 7, part 5): the same cyclic scene run with
// one feature switched on at a time from an all-off baseline, timed with the simulation's per-stage profile
// (drift, neighbours, contacts, kick, control) plus the runner's own time (measurements, checks, outputs =
// wall - profile total). Each variant is repeated and the best (least) time per stage is kept, which is the
// most stable statistic on a shared machine. Writes docs/profile.md.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace fl::profile {

struct Options {
  int particles = 2000;
  long steps = 4000;   // steps of undrained cyclic loading timed per variant
  int repeats = 5;
  std::string workDir;
};

struct Variant {
  std::string name;
  std::string switches;  // the scene fields changed from the baseline
};

struct Measured {
  Variant variant;
  std::array<double, 5> stageSeconds{};  // best over the repeats, per stage [s]
  double runnerSeconds = 0;              // best over the repeats: wall - profile total [s]
  double wallSeconds = 0;                // best over the repeats [s]
  double spread = 0;                     // (max - min) / min of the wall time over the repeats [-]
  long samples = 0;                      // time-series samples taken in the timed steps
  long files = 0;                        // files written in the timed steps
};

struct Result {
  Options options;
  std::vector<Measured> variants;
  double totalSeconds = 0;
  std::string machine;
};

std::vector<Variant> variants();
Result run(const Options& options, const std::function<void(const std::string&)>& log);
std::string reportMarkdown(const Result& r, const std::string& command);

}  // namespace fl::profile
