// Writes a run's results as it goes (a RunObserver): the time series and the per-cycle table as CSV
// flushed record by record (a killed run keeps every completed line), the stage summaries as JSON
// rewritten atomically after each stage, and the resolved scene. Units are in the CSV headers.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "runner.hpp"

namespace fl {

class RunOutputs final : public RunObserver {
 public:
  // Creates the files in `directory` (which must exist and be writable).
  RunOutputs(const std::string& directory, const Scene& scene);

  void onSample(const Sample& s) override;
  void onCycle(const CycleRecord& c) override;
  void onStageEnd(const StageSummary& s) override;
  void onWarning(const std::string& message) override;

  static std::string timeSeriesHeader();
  static std::string timeSeriesRow(const Sample& s);
  static std::string cycleHeader();
  static std::string cycleRow(const CycleRecord& c);

 private:
  std::string m_dir;
  AppendLog m_series;
  AppendLog m_cycles;
  AppendLog m_warnings;
  std::vector<StageSummary> m_stages;
  std::string m_sceneName;
};

// Stage summaries as a JSON document (also used by the report generator).
std::string stageSummariesJson(const std::string& sceneName, const std::vector<StageSummary>& stages);

}  // namespace fl
