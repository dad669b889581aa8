#include "app/report_study.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"

namespace fl::report {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

nlohmann::json readJson(const std::string& path) {
  try {
    return nlohmann::json::parse(slurp(path));
  } catch (const nlohmann::json::exception& e) {
    // nlohmann's parse errors say "at line L, column C"
    throw InputError(path + ": not valid JSON: " + e.what());
  }
}

// Reads a typed value; a wrong type is an InputError naming the file and the field.
template <class T>
T field(const nlohmann::json& j, const char* key, const std::string& where, T fallback) {
  if (!j.is_object() || !j.contains(key) || j.at(key).is_null()) return fallback;
  try {
    return j.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(where + ": field '" + key + "' has the wrong type (" + j.at(key).type_name() + ")");
  }
}

const std::vector<std::string> kSeriesColumns = {"step", "time_s", "stage", "cycle", "p_Pa", "q_Pa", "tau_Pa",
                                                 "gamma", "eps_v", "du_Pa", "inertial_number"};
const std::vector<std::string> kCycleColumns = {"cycle", "G_sec_Pa", "damping_ratio", "du_end_Pa", "Z_end",
                                                "eps_v_end", "failed"};

// A run restarted from a checkpoint, or re-run with --overwrite, appends to the same CSV files: the key
// (step or cycle) then falls back. The newer rows supersede the older ones from that key on, so only the
// latest history is kept. Returns how many rows were dropped.
std::size_t keepLatest(CsvTable& t, const std::string& key, bool equalRestarts) {
  const std::vector<double> k = t.column(key);
  std::vector<std::size_t> kept;
  kept.reserve(k.size());
  for (std::size_t i = 0; i < k.size(); ++i) {
    if (!kept.empty() && (k[i] < k[kept.back()] || (equalRestarts && k[i] == k[kept.back()])))
      while (!kept.empty() && k[kept.back()] >= k[i]) kept.pop_back();
    kept.push_back(i);
  }
  const std::size_t dropped = k.size() - kept.size();
  if (dropped == 0) return 0;
  for (auto& col : t.columns) {
    std::vector<double> c;
    c.reserve(kept.size());
    for (std::size_t i : kept) c.push_back(col[i]);
    col = std::move(c);
  }
  return dropped;
}

}  // namespace

double StageEnd::at(const std::string& key) const {
  const auto it = end.find(key);
  return it == end.end() ? kNaN : it->second;
}

const StageEnd* RunData::stageNamed(const std::string& n) const {
  for (const StageEnd& s : stages)
    if (s.name == n) return &s;
  return nullptr;
}

RunData loadRun(const std::string& studyDir, const std::string& name) {
  RunData r;
  r.name = name;
  r.dir = (fs::path(studyDir) / name).string();
  const fs::path dir(r.dir);
  const auto file = [&](const char* f) { return (dir / f).string(); };
  if (!fs::is_directory(dir)) {
    r.statusNote = "no results folder";
    return r;
  }
  const bool anyResult = fs::exists(file("timeseries.csv")) || fs::exists(file("cycles.csv")) ||
                         fs::exists(file("stages.json"));
  if (!anyResult) {
    r.statusNote = "folder holds no results";
    return r;
  }
  for (const char* needed : {"timeseries.csv", "cycles.csv"})
    if (!fs::exists(file(needed)))
      throw IoError(file(needed) + ": missing (the folder has other results of a run; a run always writes it)");

  // scene.json: requested stages and cycles, failure criterion, quasi-static guard
  if (fs::exists(file("scene.json"))) {
    const std::string path = file("scene.json");
    const nlohmann::json sc = readJson(path);
    if (sc.contains("stages") && sc["stages"].is_array()) {
      r.requestedStages = static_cast<int>(sc["stages"].size());
      for (const auto& st : sc["stages"])
        if (field<std::string>(st, "type", path, "") == "cyclic") r.requestedCycles = field<int>(st, "cycles", path, 0);
    }
    if (sc.contains("failure")) {
      r.failPressureFraction = field<double>(sc["failure"], "min_pressure_fraction", path, r.failPressureFraction);
      r.failStiffnessFraction = field<double>(sc["failure"], "min_stiffness_fraction", path, r.failStiffnessFraction);
    }
    if (sc.contains("guards"))
      r.warnInertialNumber = field<double>(sc["guards"], "warn_inertial_number", path, r.warnInertialNumber);
  }

  if (fs::exists(file("stages.json"))) {
    const std::string path = file("stages.json");
    const nlohmann::json js = readJson(path);
    if (!js.is_object() || !js.contains("stages") || !js["stages"].is_array())
      throw InputError(path + ": expected an object with a 'stages' array");
    for (const auto& st : js["stages"]) {
      StageEnd s;
      s.index = field<int>(st, "index", path, 0);
      s.name = field<std::string>(st, "name", path, "");
      s.type = field<std::string>(st, "type", path, "");
      s.steps = field<long>(st, "steps", path, 0);
      s.wallSeconds = field<double>(st, "wall_seconds", path, 0.0);
      s.K0 = field<double>(st, "K0", path, kNaN);
      s.ocr = field<double>(st, "OCR", path, kNaN);
      if (st.contains("end") && st["end"].is_object())
        for (const auto& [k, v] : st["end"].items())
          if (v.is_number()) s.end[k] = v.get<double>();
      r.stages.push_back(std::move(s));
    }
  }

  r.series = readCsv(file("timeseries.csv"), kSeriesColumns);
  r.cycles = readCsv(file("cycles.csv"), kCycleColumns);
  for (const CsvTable* t : {&*r.series, &*r.cycles})
    if (t->droppedPartialLine)
      r.notes.push_back(t->path + ": ignored an unfinished last line (run killed or still running)");
  for (auto [t, key, equal] : {std::tuple{&*r.series, "step", false}, std::tuple{&*r.cycles, "cycle", true}})
    if (const std::size_t n = keepLatest(*t, key, equal); n > 0)
      r.notes.push_back(t->path + ": " + std::to_string(n) + " rows superseded by rows written later with the same " +
                        key + " numbers (a restart or a re-run into the same folder appends); the latest are used");

  if (fs::exists(file("warnings.txt"))) {
    std::ifstream in(file("warnings.txt"));
    std::string line;
    while (std::getline(in, line))
      if (!line.empty() && line[0] != '#') ++r.warnings;
  }

  const int cyclesDone = static_cast<int>(r.cycles->rows());
  const bool stagesDone = !r.stages.empty() && static_cast<int>(r.stages.size()) >= std::max(r.requestedStages, 1);
  if (!stagesDone) {
    r.status = RunStatus::Incomplete;
    r.statusNote = std::to_string(r.stages.size()) + " of " + std::to_string(r.requestedStages) + " stages";
    if (r.requestedCycles > 0)
      r.statusNote += ", " + std::to_string(cyclesDone) + " of " + std::to_string(r.requestedCycles) + " cycles";
  } else if (r.requestedCycles > 0 && cyclesDone < r.requestedCycles) {
    r.status = RunStatus::Incomplete;
    r.statusNote = std::to_string(cyclesDone) + " of " + std::to_string(r.requestedCycles) + " cycles";
  } else {
    r.status = RunStatus::Complete;
  }
  return r;
}

std::vector<double> cycleColumn(const RunData& r, const std::string& column) {
  if (!r.cycles) return {};
  return r.cycles->column(column);
}

int failureCycle(const RunData& r) {
  if (!r.cycles) return 0;
  const auto& c = r.cycles->column("cycle");
  const auto& f = r.cycles->column("failed");
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f[i] != 0) return static_cast<int>(c[i]);
  return 0;
}

std::vector<std::size_t> cyclicRows(const RunData& r) {
  std::vector<std::size_t> rows;
  if (!r.series) return rows;
  const auto& c = r.series->column("cycle");
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c[i] > 0) rows.push_back(i);
  return rows;
}

std::vector<double> cycleCoordinate(const RunData& r) {
  const std::vector<std::size_t> rows = cyclicRows(r);
  std::vector<double> x(rows.size(), kNaN);
  if (rows.empty()) return x;
  const auto& cyc = r.series->column("cycle");
  const auto& t = r.series->column("time_s");
  // group the rows by cycle; a cycle starts where the previous one ended (its first row for cycle 1)
  double lastDuration = kNaN;
  std::size_t k = 0;
  double start = t[rows[0]];
  while (k < rows.size()) {
    const double c = cyc[rows[k]];
    std::size_t e = k;
    while (e + 1 < rows.size() && cyc[rows[e + 1]] == c) ++e;
    const bool closed = e + 1 < rows.size() || (r.cycles && !r.cycles->column("cycle").empty() &&
                                                r.cycles->column("cycle").back() >= c);
    double duration = t[rows[e]] - start;
    if (!closed && std::isfinite(lastDuration)) duration = lastDuration;  // unfinished cycle: as long as the last
    for (std::size_t i = k; i <= e; ++i) {
      const double f = duration > 0 ? (t[rows[i]] - start) / duration
                                    : (e > k ? static_cast<double>(i - k) / static_cast<double>(e - k) : 1.0);
      x[i] = c - 1.0 + std::clamp(f, 0.0, 1.0);
    }
    if (closed && duration > 0) lastDuration = duration;
    start = t[rows[e]];
    k = e + 1;
  }
  return x;
}

std::vector<std::size_t> rowsOfCycle(const RunData& r, int cycle) {
  const std::vector<std::size_t> rows = cyclicRows(r);
  std::vector<std::size_t> out;
  if (rows.empty()) return out;
  const auto& cyc = r.series->column("cycle");
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (cyc[rows[k]] != cycle) continue;
    if (out.empty() && k > 0 && cyc[rows[k - 1]] == cycle - 1) out.push_back(rows[k - 1]);
    out.push_back(rows[k]);
  }
  return out;
}

MedianMax cyclicMedianMax(const RunData& r, const std::string& column) {
  std::vector<double> v;
  if (r.series && r.series->has(column)) {
    const auto& c = r.series->column(column);
    for (std::size_t i : cyclicRows(r))
      if (std::isfinite(c[i])) v.push_back(c[i]);
  }
  if (v.empty()) return {kNaN, kNaN};
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return {median, v.back()};
}

}  // namespace fl::report
