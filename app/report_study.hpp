/*
 * One results folder of a study, as the report generator sees it: the stage summaries (stages.json),
 * the time series and per-cycle table (CSV), the failure criterion and requested cycles (scene.json) and
 * the count of run-time warnings. A folder that does not exist, or holds none of the result files, is a
 * run that was "not run"; a folder with results but without timeseries.csv or cycles.csv, or with a
 * garbled file, is an error naming the file (and line/column for CSV, line/column for JSON).
 * Plus the per-run quantities the report compares with the paper. No Qt, no VTK.
 */
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "app/report_csv.hpp"

namespace fl::report {

struct StageEnd {
  int index = 0;
  std::string name, type;
  long steps = 0;
  double wallSeconds = 0, K0 = 0, ocr = 0;
  std::map<std::string, double> end;  // the end sample's fields (stages.json "end")
  double at(const std::string& key) const;  // NaN when absent
};

enum class RunStatus { NotRun, Incomplete, Complete };

struct RunData {
  std::string name, dir;
  RunStatus status = RunStatus::NotRun;
  std::string statusNote;          // why incomplete / not run
  std::vector<StageEnd> stages;    // stages.json (empty if none yet)
  std::optional<CsvTable> series;  // timeseries.csv
  std::optional<CsvTable> cycles;  // cycles.csv
  int requestedStages = 0;         // scene.json stages (a prestrain stage reports two summaries)
  int requestedCycles = 0;         // cycles of the scene's cyclic stage (0: none)
  double failPressureFraction = 0.2, failStiffnessFraction = 0.2;  // scene.json "failure"
  double warnInertialNumber = 1e-3;                                 // scene.json guards
  int warnings = 0;                // lines of warnings.txt (comments excluded)
  std::vector<std::string> notes;  // e.g. an unfinished last CSV line that was ignored

  bool present() const { return status != RunStatus::NotRun; }
  bool hasCycles() const { return cycles && cycles->rows() > 0; }
  const StageEnd* lastStage() const { return stages.empty() ? nullptr : &stages.back(); }
  const StageEnd* stageNamed(const std::string& name) const;  // first stage with that name
};

// Loads <studyDir>/<name>. Throws InputError/IoError naming the file for garbled or missing files.
RunData loadRun(const std::string& studyDir, const std::string& name);

// Per-cycle column (cycles.csv) or an empty vector.
std::vector<double> cycleColumn(const RunData& r, const std::string& column);

// First cycle flagged failed (cycles.csv 'failed'), 0 if none.
int failureCycle(const RunData& r);

// Rows of the time series that belong to the cyclic stage (cycle > 0).
std::vector<std::size_t> cyclicRows(const RunData& r);

// A continuous cycle coordinate for each time-series row of the cyclic stage (same order as cyclicRows):
// cycle c spans (c - 1, c]; inside a cycle the coordinate is proportional to time (strain-controlled at a
// constant rate, so proportional to strain travelled).
std::vector<double> cycleCoordinate(const RunData& r);

// The time-series rows of one cycle, starting with the last point of the previous cycle so the loop closes.
std::vector<std::size_t> rowsOfCycle(const RunData& r, int cycle);

// Median and maximum of a time-series column over the cyclic stage (NaN if none).
struct MedianMax {
  double median = 0, max = 0;
};
MedianMax cyclicMedianMax(const RunData& r, const std::string& column);

}  // namespace fl::report
