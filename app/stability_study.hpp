// The full-size numerical-stability study (issue 7, part 3): the cases of the reduced CI suite
// (stability_cases.hpp) at full size, from two specimens — the suite's standard one (compression friction
// 0.1) and a jammed dense one (frictionless compression) — plus the loose gas and the 10:1 size ratio.
// Reported per case: outcome (ran bounded / stopped with a diagnostic / failed), max overlap / r,
// energy-balance error, dt used against the Rayleigh step and the stiffness-based critical step, wall time.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "stability_cases.hpp"

namespace fl::stability {

struct StudyOptions {
  int count = 4000;     // spheres of every specimen and gas case
  int jobs = 1;         // cases run in parallel (results do not depend on it)
  std::string workDir;  // specimens and diagnostic checkpoints go here
};

struct CaseResult {
  std::string specimen;  // "standard (mu_c 0.1)", "jammed dense (mu_c 0)", "gas"
  std::string name;
  bool mayStop = false;
  double overlapLimit = kOverlapBound;
  Outcome outcome;
  std::string otherError;  // an error that is not a diagnostic stop (a failure of the suite)
  std::string verdict;     // "ran bounded", "stopped with a diagnostic", "FAILED: ..."
  bool contractHolds = false;  // ran bounded, or stopped with a diagnostic that says how to fix it
  bool asExpected = false;     // and matches the reduced test's expectation (completes unless mayStop)
};

struct SpecimenState {
  std::string name;
  double muC = 0, p = 0, voidRatio = 0, Z = 0, seconds = 0;
};

struct StudyResult {
  StudyOptions options;
  std::vector<SpecimenState> specimens;
  std::vector<CaseResult> cases;
  double wallSeconds = 0, cpuSeconds = 0;
  std::string machine;
};

// Classifies an outcome against the suite's contract (pure; tested).
void classify(CaseResult& c);

StudyResult runStudy(const StudyOptions& options, const std::function<void(const std::string&)>& log);
std::string reportMarkdown(const StudyResult& r, const std::string& command);

}  // namespace fl::stability
