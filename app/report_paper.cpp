#include "app/report_paper.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <utility>

#include "app/report_study.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "ui/chart_render.hpp"

namespace fl::report {

namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Judgement thresholds (stated in the report).
constexpr double kFlatPercent = 0.5;      // |first -> last change| below this [%]: "flat"
constexpr double kDuTolerance = 100.0;    // |Delta u| below this [Pa] counts as zero
constexpr double kEpsTolerance = 1e-6;    // |eps_v| below this [-] counts as zero
constexpr double kSameAmplitude = 10.0;   // spread of tau amplitudes below this [%]: "independent of history"

// ---- the paper's numbers (text of the paper; section names as printed) --------------------------------
constexpr double kPaperVoidIso = 0.528, kPaperVoidAniso = 0.553;  // "Simulation approach"
constexpr double kPaperAIso = 0.018, kPaperAAniso = 0.213;        // "Simulation approach", eq. (2)
constexpr double kPaperP = 318e3;                                 // [Pa] "Simulation approach"
constexpr double kPaperOcr = 4.5;                                 // "Simulation approach", Table 2
constexpr int kPaperFailureCycle = 67;   // "Undrained cyclic loading / Effect of depositional history", Figs 5, 6b
constexpr int kPaperCycles = 100;        // "Introduction"
const char* const kSecSim = "§ Simulation approach";
const char* const kSecUndrCons = "§ Undrained cyclic loading: effect of consolidation history";
const char* const kSecUndrDep = "§ Undrained cyclic loading: effect of depositional history";
const char* const kSecDrCons = "§ Drained cyclic loading: effect of consolidation history";
const char* const kSecDrDep = "§ Drained cyclic loading: effect of depositional history";

struct History {
  const char* key;     // folder part
  const char* label;   // for people
  const char* paperG;  // G_sec trend in Fig. 4a
  const char* paperZ;  // Z trend in Fig. 4b (and Fig. 9a, drained)
  bool paperNegativeDu;  // Fig. 3: negative Delta u occurs
  char duPanel;          // panel of Fig. 3 with its Delta u
  char loopPanel;        // panel of Fig. 2 with its tau-gamma loops (Fig. 7: the same letter)
};
const History kHistories[] = {
    {"isotropic", "isotropic consolidation", "degrades", "decreases", true, 'a', 'd'},
    {"k0", "K0 consolidation", "hardens", "increases", true, 'b', 'e'},
    {"ocr", "OCR = 4.5", "hardens", "increases", false, 'c', 'f'},
};

std::string runName(const std::string& fabric, const std::string& hist, const std::string& drainage) {
  return "run-" + fabric + "-" + hist + "-" + drainage;
}

// ---- formatting ----------------------------------------------------------------------------------------
std::string fmt(double v, int prec) {
  if (!std::isfinite(v)) return "—";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", prec, v);
  return b;
}
std::string fmtSigned(double v, int prec) {
  if (!std::isfinite(v)) return "—";
  char b[64];
  std::snprintf(b, sizeof b, "%+.*f", prec, v);
  return b;
}
std::string fmtE(double v) {
  if (!std::isfinite(v)) return "—";
  char b[64];
  std::snprintf(b, sizeof b, "%.2e", v);
  return b;
}
std::string pct(double v) { return std::isfinite(v) ? fmtSigned(v, 1) + " %" : "—"; }
std::string kPa(double pa, int prec = 1) { return std::isfinite(pa) ? fmt(pa / 1e3, prec) + " kPa" : "—"; }
std::string MPa(double pa) { return std::isfinite(pa) ? fmt(pa / 1e6, 1) + " MPa" : "—"; }
std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string o;
  for (std::size_t i = 0; i < v.size(); ++i) o += (i ? sep : "") + v[i];
  return o;
}
std::string code(const std::string& s) { return "`" + s + "`"; }

struct Table {
  std::vector<std::string> head;
  std::vector<std::vector<std::string>> rows;
  std::string str() const {
    std::string o = "| " + join(head, " | ") + " |\n|";
    for (std::size_t i = 0; i < head.size(); ++i) o += "---|";
    o += "\n";
    for (const auto& r : rows) o += "| " + join(r, " | ") + " |\n";
    return o + "\n";
  }
};

// ---- per-run quantities ----------------------------------------------------------------------------------
double endValue(const RunData& r, const std::string& key) {
  const StageEnd* s = r.lastStage();
  return s ? s->at(key) : kNaN;
}

struct Change {
  double first = kNaN, last = kNaN, percent = kNaN;
  int firstCycle = 0, lastCycle = 0;
};
Change change(const RunData& r, const std::string& column) {
  Change c;
  if (!r.hasCycles()) return c;
  const auto& v = r.cycles->column(column);
  const auto& n = r.cycles->column("cycle");
  c.first = v.front();
  c.last = v.back();
  c.firstCycle = static_cast<int>(n.front());
  c.lastCycle = static_cast<int>(n.back());
  if (v.size() >= 2 && c.first != 0) c.percent = (c.last - c.first) / std::abs(c.first) * 100.0;
  return c;
}
std::string trendWord(double percent, const char* up, const char* down) {
  if (!std::isfinite(percent)) return "—";
  if (percent > kFlatPercent) return up;
  if (percent < -kFlatPercent) return down;
  return "flat";
}
std::string gTrend(const RunData& r) { return trendWord(change(r, "G_sec_Pa").percent, "hardens", "degrades"); }
std::string zTrend(const RunData& r) { return trendWord(change(r, "Z_end").percent, "increases", "decreases"); }
std::string agree(const std::string& ours, const std::string& paper) {
  if (ours == "—" || paper.empty()) return "—";
  return ours == paper ? "same" : "differs";
}

double minOf(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x) && !(x >= m)) m = x;
  return m;
}
double maxOf(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x) && !(x <= m)) m = x;
  return m;
}
double lastOf(const std::vector<double>& v) { return v.empty() ? kNaN : v.back(); }
double seriesMax(const RunData& r, const std::string& column) {
  return r.series && r.series->has(column) ? maxOf(r.series->column(column)) : kNaN;
}
double tauAmplitudeLast(const RunData& r) {
  if (!r.hasCycles()) return kNaN;
  return 0.5 * (lastOf(r.cycles->column("tau_max_Pa")) - lastOf(r.cycles->column("tau_min_Pa")));
}
char signOf(double v, double tol) { return !std::isfinite(v) ? '?' : v > tol ? '+' : v < -tol ? '-' : '0'; }

// Largest one-cycle drop of Z_end (the paper sees failure as a sharp drop of Z, Fig. 6b).
std::pair<int, double> largestZDrop(const RunData& r) {
  if (!r.hasCycles()) return {0, kNaN};
  const auto& z = r.cycles->column("Z_end");
  const auto& n = r.cycles->column("cycle");
  int at = 0;
  double drop = 0;
  for (std::size_t i = 1; i < z.size(); ++i)
    if (z[i - 1] - z[i] > drop) {
      drop = z[i - 1] - z[i];
      at = static_cast<int>(n[i]);
    }
  return {at, drop};
}

const StageEnd* nthStageOfType(const RunData& r, const std::string& type, int n) {
  for (const StageEnd& s : r.stages)
    if (s.type == type && n-- == 0) return &s;
  return nullptr;
}

std::string statusText(const RunData& r) {
  switch (r.status) {
    case RunStatus::NotRun: return "not run";
    case RunStatus::Incomplete: return "incomplete (" + r.statusNote + ")";
    case RunStatus::Complete: return "complete";
  }
  return "";
}

std::string describe(const std::string& folder, int cycles) {
  static const std::map<std::string, std::string> fixed = {
      {"specimen-isotropic", "isotropic fabric: deposition to 50 kPa"},
      {"specimen-anisotropic", "anisotropic fabric: pre-strain, re-consolidation to 50 kPa"},
      {"history-isotropic-isotropic", "isotropic fabric, isotropic consolidation to 318 kPa"},
      {"history-isotropic-k0", "isotropic fabric, K0 consolidation to p′ = 318 kPa"},
      {"history-isotropic-ocr", "isotropic fabric, K0 loading and unloading to p′ = 318 kPa (OCR = 4.5)"},
      {"history-anisotropic-isotropic", "anisotropic fabric, isotropic consolidation to 318 kPa"}};
  if (auto it = fixed.find(folder); it != fixed.end()) return it->second;
  // run-<fabric>-<history>-<drainage>[-md]
  std::string s = folder.substr(4);
  const bool md = s.size() > 3 && s.compare(s.size() - 3, 3, "-md") == 0;
  if (md) s.resize(s.size() - 3);
  const auto a = s.find('-'), b = s.rfind('-');
  if (a == std::string::npos || b == a) return folder;
  const std::string fabric = s.substr(0, a), hist = s.substr(a + 1, b - a - 1), drainage = s.substr(b + 1);
  std::string histLabel = hist;
  for (const History& h : kHistories)
    if (hist == h.key) histLabel = h.label;
  std::string d = fabric + " fabric, " + histLabel + ", " + drainage + ", " +
                  std::to_string(cycles > 0 ? cycles : kPaperCycles) + " cycles";
  return md ? "issue 9: " + d + ", Mindlin–Deresiewicz contact law" : "Table 2: " + d;
}

// ---- series for the charts -------------------------------------------------------------------------------
std::vector<double> pick(const RunData& r, const std::string& column, const std::vector<std::size_t>& rows, double scale) {
  std::vector<double> out;
  const auto& c = r.series->column(column);
  out.reserve(rows.size());
  for (std::size_t i : rows) out.push_back(c[i] * scale);
  return out;
}
std::vector<std::size_t> allRows(const RunData& r) {
  std::vector<std::size_t> rows(r.series ? r.series->rows() : 0);
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = i;
  return rows;
}

charts::Series stressPath(const RunData& r, const std::string& name, bool cyclicOnly) {
  const auto rows = cyclicOnly ? cyclicRows(r) : allRows(r);
  return {name, pick(r, "p_Pa", rows, 1e-3), pick(r, "q_Pa", rows, 1e-3), false};
}
charts::Series verticalHorizontal(const RunData& r, const std::string& name) {
  const auto rows = allRows(r);
  std::vector<double> sv = pick(r, "szz_Pa", rows, 1e-3), sx = pick(r, "sxx_Pa", rows, 1e-3),
                      sy = pick(r, "syy_Pa", rows, 1e-3);
  for (std::size_t i = 0; i < sx.size(); ++i) sx[i] = 0.5 * (sx[i] + sy[i]);
  return {name, sv, sx, false};
}
charts::Series loop(const RunData& r, int cycle, const std::string& name) {
  const auto rows = rowsOfCycle(r, cycle);
  return {name, pick(r, "gamma", rows, 1.0), pick(r, "tau_Pa", rows, 1e-3), false};
}
charts::Series againstCycles(const RunData& r, const std::string& column, double scale, const std::string& name) {
  return {name, cycleCoordinate(r), pick(r, column, cyclicRows(r), scale), false};
}
charts::Series perCycle(const RunData& r, const std::string& column, double scale, const std::string& name) {
  charts::Series s{name, {}, {}, false};
  if (!r.hasCycles()) return s;
  s.x = r.cycles->column("cycle");
  for (double v : r.cycles->column(column)) s.y.push_back(v * scale);
  if (s.x.size() <= 3) s.markers = true;  // a line through one or two points says little
  return s;
}
int lastCycle(const RunData& r) {
  return r.hasCycles() ? static_cast<int>(r.cycles->column("cycle").back()) : 0;
}
// Cycles shown in loop plots: 1, 10 and the last complete one (those that exist).
std::vector<int> loopCycles(const RunData& r) {
  const int last = lastCycle(r);
  std::vector<int> c;
  if (last == 0) return cyclicRows(r).empty() ? c : std::vector<int>{1};  // first cycle still running
  c.push_back(1);
  if (last > 10) c.push_back(10);
  if (last > 1) c.push_back(last);
  return c;
}

// ---- the writer ----------------------------------------------------------------------------------------
class Writer {
 public:
  Writer(std::string study, std::string out) : m_study(std::move(study)), m_out(std::move(out)) {}

  void load() {
    for (const auto* list : {&studyFolders(), &optionalStudyFolders()})
      for (const std::string& f : *list) m_runs.emplace(f, loadRun(m_study, f));
  }
  const RunData& run(const std::string& name) const { return m_runs.at(name); }
  bool has(const std::string& name) const { return run(name).present(); }

  ReportSummary write(const std::string& notesFile);

 private:
  // Renders a figure if at least one run it needs is present; otherwise notes it as skipped.
  void figure(const std::string& file, charts::Chart chart, const std::string& caption,
              const std::vector<std::string>& needs);
  void runsSection();
  void summarySection();
  void consolidationSection();
  void undrainedHistorySection();
  void undrainedFabricSection();
  void drainedSection();
  void consistencySection();
  void inertialSection();
  void contactLawSection();
  void notesSection(const std::string& notesFile);
  void dataNotesSection();

  std::string m_study, m_out;
  std::map<std::string, RunData> m_runs;
  std::string m_md;
  std::vector<std::string> m_figures, m_skipped;
};

void Writer::figure(const std::string& file, charts::Chart chart, const std::string& caption,
                    const std::vector<std::string>& needs) {
  std::vector<std::string> missing;
  for (const std::string& n : needs)
    if (!has(n)) missing.push_back(n);
  std::erase_if(chart.series, [](const charts::Series& s) { return s.x.empty() || s.y.empty(); });
  if (missing.size() == needs.size() || chart.series.empty()) {
    const std::string why = missing.size() == needs.size() ? "not run: " + join(missing, ", ") : "no data yet";
    m_skipped.push_back(file + " (" + why + ")");
    m_md += "*" + code(file) + " skipped (" + why + "): " + caption + "*\n\n";
    return;
  }
  charts::renderPng(chart, (fs::path(m_out) / file).string());
  m_figures.push_back(file);
  m_md += "![" + chart.title + "](" + file + ")\n\n*" + caption;
  if (!missing.empty()) m_md += " Not run, so not shown: " + join(missing, ", ") + ".";
  m_md += "*\n\n";
}

void Writer::runsSection() {
  m_md += "## The runs\n\n";
  Table t{{"folder", "what", "status", "stages", "cycles", "warnings"}, {}};
  for (const std::string& f : studyFolders()) {
    const RunData& r = run(f);
    t.rows.push_back({code(f), describe(f, r.requestedCycles), statusText(r), r.present() ? std::to_string(r.stages.size()) : "—",
                      r.present() ? std::to_string(r.cycles->rows()) : "—",
                      r.present() ? std::to_string(r.warnings) : "—"});
  }
  for (const std::string& f : optionalStudyFolders()) {
    const RunData& r = run(f);
    t.rows.push_back({code(f), describe(f, r.requestedCycles) + " (optional)", statusText(r),
                      r.present() ? std::to_string(r.stages.size()) : "—",
                      r.present() ? std::to_string(r.cycles->rows()) : "—",
                      r.present() ? std::to_string(r.warnings) : "—"});
  }
  m_md += t.str();
  m_md += "Warnings are the lines of each folder's `warnings.txt` (quasi-static regime left, energy drift, "
          "time-step changes).\n\n";
}

void Writer::summarySection() {
  m_md += "## The paper's numbers beside ours\n\n";
  m_md += "Paper values are quoted from its text (section, table or figure in the third column). \"Comparison\" "
          "gives our value minus the paper's, or whether a qualitative trend is the same. A trend is \"flat\" when "
          "the change from the first to the last cycle is within ±" + fmt(kFlatPercent, 1) + " %.\n\n";
  Table t{{"quantity", "paper", "where in the paper", "FabricLab", "comparison"}, {}};

  // void ratios before shearing
  {
    std::vector<std::string> ours, diffs;
    for (const History& h : kHistories) {
      const RunData& r = run(std::string("history-isotropic-") + h.key);
      const double e = endValue(r, "void_ratio");
      ours.push_back(h.key + std::string(" ") + fmt(e, 3));
      diffs.push_back(fmtSigned(e - kPaperVoidIso, 3));
    }
    t.rows.push_back({"void ratio e before cycling, isotropic fabric (p′ = 318 kPa)",
                      fmt(kPaperVoidIso, 3) + " for every history", kSecSim, join(ours, " · "), join(diffs, " · ")});
  }
  const double eIso = endValue(run("history-isotropic-isotropic"), "void_ratio");
  const double eAniso = endValue(run("history-anisotropic-isotropic"), "void_ratio");
  t.rows.push_back({"void ratio e before cycling, anisotropic fabric", fmt(kPaperVoidAniso, 3), kSecSim,
                    fmt(eAniso, 3), fmtSigned(eAniso - kPaperVoidAniso, 3)});
  t.rows.push_back({"e(anisotropic) − e(isotropic), isotropic consolidation",
                    fmtSigned(kPaperVoidAniso - kPaperVoidIso, 3), kSecSim, fmtSigned(eAniso - eIso, 3),
                    fmtSigned((eAniso - eIso) - (kPaperVoidAniso - kPaperVoidIso), 3)});
  // fabric anisotropy
  for (const auto& [fabric, paperA] : {std::pair<std::string, double>{"isotropic", kPaperAIso}, {"anisotropic", kPaperAAniso}}) {
    const RunData& sp = run("specimen-" + fabric);
    const RunData& hi = run("history-" + fabric + "-isotropic");
    const double a50 = endValue(sp, "a_2D_RB"), a318 = endValue(hi, "a_2D_RB");
    t.rows.push_back({"fabric anisotropy a, " + fabric + " specimen", fmt(paperA, 3) + " (Rothenburg–Bathurst)",
                      std::string(kSecSim) + ", eq. (2)",
                      "a_2D_RB " + fmt(a50, 3) + " at 50 kPa, " + fmt(a318, 3) + " at 318 kPa (a_3D " +
                          fmt(endValue(sp, "a_3D"), 3) + ", " + fmt(endValue(hi, "a_3D"), 3) + ")",
                      fmtSigned(a50 - paperA, 3) + " at 50 kPa"});
  }
  // p' before cycling
  {
    std::vector<std::string> ours;
    double worst = kNaN;
    for (const char* h : {"history-isotropic-isotropic", "history-isotropic-k0", "history-isotropic-ocr",
                          "history-anisotropic-isotropic"}) {
      const double p = endValue(run(h), "p_Pa");
      ours.push_back(kPa(p));
      const double d = (p - kPaperP) / kPaperP * 100;
      if (std::isfinite(d) && !(std::abs(d) <= std::abs(worst))) worst = d;
    }
    t.rows.push_back({"p′ at the start of cycling (iso · K0 · OCR · anisotropic fabric)", kPa(kPaperP, 0), kSecSim,
                      join(ours, " · "), "worst " + pct(worst)});
  }
  // OCR, K0
  const RunData& ocrHist = run("history-isotropic-ocr");
  const StageEnd* ocrEnd = ocrHist.lastStage();
  const double ocr = ocrEnd ? ocrEnd->ocr : kNaN;
  t.rows.push_back({"over-consolidation ratio OCR = σ′v,max / σ′v", fmt(kPaperOcr, 1), std::string(kSecSim) + "; Table 2",
                    fmt(ocr, 2), fmtSigned(ocr - kPaperOcr, 2)});
  {
    const StageEnd* k0End = run("history-isotropic-k0").lastStage();
    const StageEnd* load = nthStageOfType(ocrHist, "k0", 0);
    t.rows.push_back({"K0 = σ′h/σ′v after K0 loading", "not stated (path only)", "Fig. 1; Fig. 2b",
                      "K0 history " + fmt(k0End ? k0End->K0 : kNaN, 3) + " · OCR history " +
                          fmt(load ? load->K0 : kNaN, 3),
                      "—"});
  }
  // failure
  const RunData& anisoU = run(runName("anisotropic", "isotropic", "undrained"));
  {
    const int fc = failureCycle(anisoU);
    std::string ours = !anisoU.present() ? "not run"
                       : fc > 0          ? "cycle " + std::to_string(fc)
                                         : "none in " + std::to_string(lastCycle(anisoU)) + " cycles";
    const std::string cmp = !anisoU.present() ? "—"
                            : fc > 0          ? fmtSigned(fc - kPaperFailureCycle, 0) + " cycles"
                                              : "no failure";
    t.rows.push_back({"failure cycle, anisotropic fabric, undrained", std::to_string(kPaperFailureCycle),
                      std::string(kSecUndrDep) + "; Figs 5, 6b", ours + " (our criterion, see § 3)", cmp});
  }
  {
    std::vector<std::string> failing, ran;
    for (const std::string& f : studyFolders()) {
      if (f.rfind("run-", 0) != 0 || f == anisoU.name || !has(f)) continue;
      ran.push_back(f);
      if (const int fc = failureCycle(run(f)); fc > 0) failing.push_back(f + " (cycle " + std::to_string(fc) + ")");
    }
    t.rows.push_back({"failure of the other seven runs", "none in 100 cycles (failure \"in one of the specimens\")",
                      "§ Introduction; Fig. 5", ran.empty() ? "not run" : failing.empty() ? "none of " + std::to_string(ran.size()) : join(failing, ", "),
                      ran.empty() ? "—" : failing.empty() ? "same" : "differs"});
  }
  // trends, undrained (Fig. 4)
  for (const History& h : kHistories) {
    const RunData& r = run(runName("isotropic", h.key, "undrained"));
    const Change g = change(r, "G_sec_Pa");
    t.rows.push_back({std::string("G_sec trend, undrained, ") + h.label, h.paperG, std::string("Fig. 4a; ") + kSecUndrCons,
                      r.present() ? pct(g.percent) + " (" + gTrend(r) + ")" : "not run", agree(gTrend(r), h.paperG)});
  }
  for (const History& h : kHistories) {
    const RunData& r = run(runName("isotropic", h.key, "undrained"));
    const Change z = change(r, "Z_end");
    t.rows.push_back({std::string("Z trend, undrained, ") + h.label, h.paperZ, "Fig. 4b",
                      r.present() ? pct(z.percent) + " (" + zTrend(r) + ")" : "not run", agree(zTrend(r), h.paperZ)});
  }
  // pore pressure sign
  for (const History& h : kHistories) {
    const RunData& r = run(runName("isotropic", h.key, "undrained"));
    const double duMin = minOf(cycleColumn(r, "du_min_Pa"));
    const std::string ours = !r.present() ? "not run"
                             : !std::isfinite(duMin) ? "—"
                             : duMin < -kDuTolerance ? "yes: min Δu = " + kPa(duMin)
                                                     : "no: min Δu = " + kPa(duMin);
    const std::string oursWord = !r.present() || !std::isfinite(duMin) ? "—" : duMin < -kDuTolerance ? "yes" : "no";
    t.rows.push_back({std::string("negative Δu during cycling, ") + h.label, h.paperNegativeDu ? "yes" : "no (never negative)",
                      std::string("Fig. 3") + h.duPanel + "; " + kSecUndrCons,
                      ours, agree(oursWord, h.paperNegativeDu ? "yes" : "no")});
  }
  // tau amplitude independent of history (Fig. 3 second row)
  {
    std::vector<double> amps;
    std::vector<std::string> shown;
    for (const History& h : kHistories) {
      const double a = tauAmplitudeLast(run(runName("isotropic", h.key, "undrained")));
      shown.push_back(kPa(a));
      if (std::isfinite(a)) amps.push_back(a);
    }
    double spread = kNaN;
    if (amps.size() >= 2) {
      const double mean = (std::accumulate(amps.begin(), amps.end(), 0.0)) / static_cast<double>(amps.size());
      spread = (maxOf(amps) - minOf(amps)) / mean * 100;
    }
    t.rows.push_back({"τ amplitude (last cycle) independent of consolidation history", "yes", "Figs 3d–f",
                      join(shown, " · ") + "; spread " + (std::isfinite(spread) ? fmt(spread, 1) + " %" : "—"),
                      !std::isfinite(spread) ? "—" : spread < kSameAmplitude ? "same (spread < " + fmt(kSameAmplitude, 0) + " %)"
                                                                             : "differs (spread ≥ " + fmt(kSameAmplitude, 0) + " %)"});
  }
  // anisotropic softer
  {
    const RunData& iso = run(runName("isotropic", "isotropic", "undrained"));
    const double ratio = change(anisoU, "G_sec_Pa").first / change(iso, "G_sec_Pa").first;
    t.rows.push_back({"G_sec,1 anisotropic / isotropic fabric, undrained", "< 1 (\"considerably softer\")",
                      std::string("Figs 5b, 6a; ") + kSecUndrDep, fmt(ratio, 2),
                      !std::isfinite(ratio) ? "—" : ratio < 1 ? "same" : "differs"});
  }
  // drained Z trend same as undrained (Fig. 9a vs 4b)
  for (const History& h : kHistories) {
    const RunData& d = run(runName("isotropic", h.key, "drained"));
    t.rows.push_back({std::string("Z trend, drained, ") + h.label, std::string(h.paperZ) + " (as Fig. 4b)",
                      std::string("Fig. 9a; ") + kSecDrCons,
                      d.present() ? pct(change(d, "Z_end").percent) + " (" + zTrend(d) + ")" : "not run",
                      agree(zTrend(d), h.paperZ)});
  }
  // drained/undrained consistency (Fig. 8 vs 3)
  {
    int pairs = 0, consistent = 0;
    for (const auto& [fabric, hist] : {std::pair<const char*, const char*>{"isotropic", "isotropic"}, {"isotropic", "k0"},
                                       {"isotropic", "ocr"}, {"anisotropic", "isotropic"}}) {
      const RunData& u = run(runName(fabric, hist, "undrained"));
      const RunData& d = run(runName(fabric, hist, "drained"));
      if (!u.hasCycles() || !d.hasCycles()) continue;
      ++pairs;
      if (signOf(lastOf(u.cycles->column("du_end_Pa")), kDuTolerance) ==
          signOf(lastOf(d.cycles->column("eps_v_end")), kEpsTolerance))
        ++consistent;
    }
    t.rows.push_back({"sign of Δu (undrained) = sign of ε_v (drained, compression +), end of last cycle",
                      "yes (\"entirely consistent\")", std::string("Fig. 8 vs Fig. 3; ") + kSecDrCons,
                      pairs ? std::to_string(consistent) + " of " + std::to_string(pairs) + " pairs" : "no pair run",
                      pairs == 0 ? "—" : consistent == pairs ? "same" : "differs"});
  }
  m_md += t.str();
  m_md += "Fabric anisotropy: `a_2D_RB` is Rothenburg and Bathurst's *a* (the paper's eq. 2, E(θ) = (1/2π)"
          "[1 + a cos 2(θ − θ_a)]) fitted to the contact normals projected on the vertical planes, the paper's "
          "measure; `a_3D` = 5/2 (φ_zz − φ_xx) from the deviatoric part of the 3D fabric tensor φ = ⟨n ⊗ n⟩. "
          "Both are 0 for isotropic contact normals. The paper does not say at which pressure it measured a; we "
          "give both the specimen at 50 kPa and the specimen consolidated to 318 kPa. The paper also gives relative "
          "densities (92 % and 63 %), which need e_min and e_max of the material and are not reproduced.\n\n";
}

void Writer::consolidationSection() {
  m_md += "## 1. Specimens and consolidation histories (paper Figure 1)\n\n";
  Table t{{"folder", "stage", "p′", "q", "e", "Z", "a_2D_RB", "a_3D", "K0 = σ′h/σ′v", "OCR"}, {}};
  for (const char* f : {"specimen-isotropic", "specimen-anisotropic", "history-isotropic-isotropic", "history-isotropic-k0",
                        "history-isotropic-ocr", "history-anisotropic-isotropic"}) {
    const RunData& r = run(f);
    if (!r.present()) {
      t.rows.push_back({code(f), "not run", "", "", "", "", "", "", "", ""});
      continue;
    }
    for (const StageEnd& s : r.stages)
      t.rows.push_back({code(f), s.name, kPa(s.at("p_Pa")), kPa(s.at("q_Pa")), fmt(s.at("void_ratio"), 3),
                        fmt(s.at("Z"), 2), fmt(s.at("a_2D_RB"), 3), fmt(s.at("a_3D"), 3), fmt(s.K0, 3), fmt(s.ocr, 2)});
  }
  m_md += "End state of every stage (`stages.json`); OCR = σ′v,max over the whole run / σ′v at the stage end.\n\n";
  m_md += t.str();

  const RunData& ocrHist = run("history-isotropic-ocr");
  const StageEnd* load = nthStageOfType(ocrHist, "k0", 0);
  const StageEnd* unload = nthStageOfType(ocrHist, "k0", 1);
  const StageEnd* k0End = run("history-isotropic-k0").lastStage();
  const double svMax = seriesMax(ocrHist, "szz_Pa");
  if (ocrHist.present())
    m_md += "Over-consolidation: K0 loading to σ′v,max = " + kPa(svMax) + " (K0 = " + fmt(load ? load->K0 : kNaN, 3) +
            " at its end), K0 unloading until the stress is isotropic (K0 = " + fmt(unload ? unload->K0 : kNaN, 3) +
            ", OCR = " + fmt(unload ? unload->ocr : kNaN, 2) + "), then to p′ = 318 kPa: OCR = " +
            fmt(ocrHist.lastStage() ? ocrHist.lastStage()->ocr : kNaN, 2) + " (paper: " + fmt(kPaperOcr, 1) + ").\n\n";

  charts::Chart c{"Consolidation paths (paper Fig. 1)", "mean effective stress p′ (kPa)", "q = σ′v − σ′h (kPa)",
                  false, false, {}, 900, 600};
  for (const auto& [f, label] : {std::pair<const char*, const char*>{"history-isotropic-isotropic", "isotropic fabric, isotropic"},
                                 {"history-isotropic-k0", "isotropic fabric, K0"},
                                 {"history-isotropic-ocr", "isotropic fabric, OCR = 4.5"},
                                 {"history-anisotropic-isotropic", "anisotropic fabric, isotropic"}})
    if (has(f)) c.series.push_back(stressPath(run(f), label, false));
  figure("fig-01-consolidation-q-p.png", c,
         "Stress paths of the four consolidation histories from the 50 kPa specimens to p′ = 318 kPa (paper Fig. 1).",
         {"history-isotropic-isotropic", "history-isotropic-k0", "history-isotropic-ocr", "history-anisotropic-isotropic"});

  charts::Chart v{"K0 loading and unloading: σ′h against σ′v", "vertical effective stress σ′v (kPa)",
                  "horizontal effective stress σ′h (kPa)", false, false, {}, 900, 600};
  double top = 0;
  for (const auto& [f, label] : {std::pair<const char*, const char*>{"history-isotropic-k0", "K0 consolidation"},
                                 {"history-isotropic-ocr", "OCR = 4.5 history"}})
    if (has(f)) {
      v.series.push_back(verticalHorizontal(run(f), label));
      top = std::max(top, maxOf(v.series.back().x));
    }
  if (!v.series.empty() && top > 0) {
    v.series.push_back({"σ′h = σ′v", {0.0, top}, {0.0, top}, false});
    if (k0End && std::isfinite(k0End->K0))
      v.series.push_back({"K0 = " + fmt(k0End->K0, 3) + " (K0 history)", {0.0, top}, {0.0, k0End->K0 * top}, false});
    if (load && std::isfinite(load->K0) && (!k0End || std::abs(load->K0 - k0End->K0) > 1e-3))
      v.series.push_back({"K0 = " + fmt(load->K0, 3) + " (OCR loading)", {0.0, top}, {0.0, load->K0 * top}, false});
  }
  figure("fig-01-consolidation-sv-sh.png", v,
         "Horizontal against vertical effective stress for K0 consolidation and for over-consolidation (OCR = " +
             fmt(ocrHist.lastStage() ? ocrHist.lastStage()->ocr : kNaN, 2) +
             "); straight lines through the origin have slope K0 (loading) and 1 (isotropic).",
         {"history-isotropic-k0", "history-isotropic-ocr"});
}

// Per-history figures of one drainage and fabric group.
void Writer::undrainedHistorySection() {
  m_md += "## 2. Undrained cycles, effect of consolidation history (paper Figures 2–4)\n\n";
  Table t{{"history", "G_sec cycle 1", "G_sec last", "change", "trend (paper Fig. 4a)", "Z cycle 1", "Z last", "change",
           "trend (paper Fig. 4b)", "min Δu", "max Δu", "Δu end", "τ amplitude, last cycle"}, {}};
  std::vector<std::string> needs;
  for (const History& h : kHistories) {
    const std::string n = runName("isotropic", h.key, "undrained");
    needs.push_back(n);
    const RunData& r = run(n);
    if (!r.present()) {
      t.rows.push_back({h.label, "not run", "", "", "", "", "", "", "", "", "", "", ""});
      continue;
    }
    const Change g = change(r, "G_sec_Pa"), z = change(r, "Z_end");
    t.rows.push_back({h.label, MPa(g.first), MPa(g.last) + " (cycle " + std::to_string(g.lastCycle) + ")", pct(g.percent),
                      gTrend(r) + " (" + h.paperG + ")", fmt(z.first, 3), fmt(z.last, 3), pct(z.percent),
                      zTrend(r) + " (" + h.paperZ + ")", kPa(minOf(cycleColumn(r, "du_min_Pa"))),
                      kPa(maxOf(cycleColumn(r, "du_max_Pa"))), kPa(lastOf(cycleColumn(r, "du_end_Pa"))),
                      kPa(tauAmplitudeLast(r))});
  }
  m_md += t.str();
  m_md += "G_sec = (τ_max − τ_min)/(γ_max − γ_min) per cycle (the paper's definition, " + std::string(kSecUndrCons) +
          "); Z at the end of each cycle; Δu = σ′3,0 − σ′3. The paper reports that the isotropically consolidated "
          "specimen degrades while the K0 and over-consolidated ones harden, that Z follows G_sec, and that the "
          "over-consolidated specimen never shows a negative Δu.\n\n";

  charts::Chart sp{"Undrained stress paths, isotropic fabric (paper Fig. 2a–c)", "p′ (kPa)", "q = σ′v − σ′h (kPa)",
                   false, false, {}, 900, 600};
  for (const History& h : kHistories)
    if (has(runName("isotropic", h.key, "undrained")))
      sp.series.push_back(stressPath(run(runName("isotropic", h.key, "undrained")), h.label, true));
  figure("fig-02-undrained-stress-paths.png", sp,
         "q–p′ paths of the undrained cycles after the three consolidation histories, isotropic fabric (paper Fig. 2a–c, "
         "overlaid on one scale).",
         needs);
  for (const History& h : kHistories) {
    const std::string n = runName("isotropic", h.key, "undrained");
    charts::Chart lc{std::string("τ–γ loops, undrained, ") + h.label + " (paper Fig. 2" + h.loopPanel + ")",
                     "shear strain γ = ε_a − ε_r (−)", "shear stress τ = q/2 (kPa)", false, false, {}, 900, 600};
    if (has(n))
      for (int c : loopCycles(run(n))) lc.series.push_back(loop(run(n), c, "cycle " + std::to_string(c)));
    figure(std::string("fig-02-undrained-loops-") + h.key + ".png", lc,
           std::string("Stress–strain loops of cycles 1, 10 and the last, undrained, isotropic fabric, ") + h.label +
               " (paper Fig. 2" + h.loopPanel + ").",
           {n});
  }
  charts::Chart du{"Excess pore pressure, undrained, isotropic fabric (paper Fig. 3a–c)", "cycles",
                   "Δu = σ′3,0 − σ′3 (kPa)", false, false, {}, 900, 600};
  charts::Chart tau{"Shear stress, undrained, isotropic fabric (paper Fig. 3d–f)", "cycles", "τ (kPa)", false, false,
                    {}, 900, 600};
  charts::Chart g{"Secant shear stiffness, undrained, isotropic fabric (paper Fig. 4a)", "cycle", "G_sec (MPa)", false,
                  false, {}, 900, 600};
  charts::Chart z{"Coordination number, undrained, isotropic fabric (paper Fig. 4b)", "cycle", "Z at cycle end (−)",
                  false, false, {}, 900, 600};
  for (const History& h : kHistories) {
    const std::string n = runName("isotropic", h.key, "undrained");
    if (!has(n)) continue;
    du.series.push_back(againstCycles(run(n), "du_Pa", 1e-3, h.label));
    tau.series.push_back(againstCycles(run(n), "tau_Pa", 1e-3, h.label));
    g.series.push_back(perCycle(run(n), "G_sec_Pa", 1e-6, h.label));
    z.series.push_back(perCycle(run(n), "Z_end", 1.0, h.label));
  }
  figure("fig-03-undrained-du.png", du, "Δu against the number of cycles for the three histories (paper Fig. 3a–c).", needs);
  figure("fig-03-undrained-tau.png", tau, "τ against the number of cycles for the three histories (paper Fig. 3d–f).", needs);
  figure("fig-04a-undrained-gsec.png", g, "G_sec per cycle for the three histories (paper Fig. 4a).", needs);
  figure("fig-04b-undrained-z.png", z, "Coordination number Z at the end of each cycle (paper Fig. 4b).", needs);
}

void Writer::undrainedFabricSection() {
  m_md += "## 3. Undrained cycles, effect of depositional history (paper Figures 5–6)\n\n";
  const std::string iso = runName("isotropic", "isotropic", "undrained"), aniso = runName("anisotropic", "isotropic", "undrained");
  const RunData& a = run(aniso);
  m_md += "Failure criterion (ours, from each run's `scene.json` `failure` section; `failed` column of `cycles.csv`): a "
          "cycle fails when its minimum p′ falls below " + fmt(a.failPressureFraction, 2) +
          " × p′ at the start of cycling (liquefaction or cyclic mobility) or its G_sec falls below " +
          fmt(a.failStiffnessFraction, 2) + " × G_sec of cycle 1; the failure cycle is the first failed cycle. The paper "
          "names no quantitative criterion: it sees failure at cycle 67 from the stress–strain response and a sharp drop "
          "of Z (Figs 5, 6b; " + kSecUndrDep + "), as cyclic mobility rather than liquefaction.\n\n";
  Table t{{"fabric", "e before cycling", "a_2D_RB before cycling", "G_sec cycle 1", "G_sec last", "change", "Z cycle 1",
           "Z last", "largest one-cycle drop of Z", "failure cycle (ours)", "failure cycle (paper)"}, {}};
  for (const auto& [fabric, n] : {std::pair<std::string, std::string>{"isotropic", iso}, {"anisotropic", aniso}}) {
    const RunData& r = run(n);
    const RunData& h = run("history-" + fabric + "-isotropic");
    const std::string paper = fabric == "anisotropic" ? std::to_string(kPaperFailureCycle) : "none in 100";
    if (!r.present()) {
      t.rows.push_back({fabric, fmt(endValue(h, "void_ratio"), 3), fmt(endValue(h, "a_2D_RB"), 3), "not run", "", "", "",
                        "", "", "", paper});
      continue;
    }
    const Change g = change(r, "G_sec_Pa"), z = change(r, "Z_end");
    const auto [dropAt, drop] = largestZDrop(r);
    const int fc = failureCycle(r);
    t.rows.push_back({fabric, fmt(endValue(h, "void_ratio"), 3), fmt(endValue(h, "a_2D_RB"), 3), MPa(g.first), MPa(g.last),
                      pct(g.percent), fmt(z.first, 3), fmt(z.last, 3),
                      dropAt > 0 ? fmt(drop, 3) + " at cycle " + std::to_string(dropAt) : "—",
                      fc > 0 ? std::to_string(fc) : "none in " + std::to_string(lastCycle(r)), paper});
  }
  m_md += t.str();

  charts::Chart sp{"Undrained stress paths, isotropic consolidation (paper Fig. 5a)", "p′ (kPa)", "q = σ′v − σ′h (kPa)",
                   false, false, {}, 900, 600};
  charts::Chart g{"Secant shear stiffness, undrained (paper Fig. 6a)", "cycle", "G_sec (MPa)", false, false, {}, 900, 600};
  charts::Chart z{"Coordination number, undrained (paper Fig. 6b)", "cycle", "Z at cycle end (−)", false, false, {}, 900, 600};
  charts::Chart du{"Excess pore pressure, undrained, isotropic consolidation", "cycles", "Δu (kPa)", false, false, {}, 900, 600};
  for (const auto& [fabric, n] : {std::pair<std::string, std::string>{"isotropic", iso}, {"anisotropic", aniso}}) {
    if (!has(n)) continue;
    const std::string label = fabric + " fabric";
    sp.series.push_back(stressPath(run(n), label, true));
    g.series.push_back(perCycle(run(n), "G_sec_Pa", 1e-6, label));
    z.series.push_back(perCycle(run(n), "Z_end", 1.0, label));
    du.series.push_back(againstCycles(run(n), "du_Pa", 1e-3, label));
  }
  figure("fig-05-fabric-undrained-stress-paths.png", sp, "q–p′ paths for the isotropic and anisotropic fabrics (paper Fig. 5a).",
         {iso, aniso});
  for (const auto& [fabric, n] : {std::pair<std::string, std::string>{"isotropic", iso}, {"anisotropic", aniso}}) {
    charts::Chart lc{"τ–γ loops, undrained, " + fabric + " fabric (paper Fig. 5b)", "shear strain γ (−)", "τ (kPa)", false,
                     false, {}, 900, 600};
    if (has(n))
      for (int c : loopCycles(run(n))) lc.series.push_back(loop(run(n), c, "cycle " + std::to_string(c)));
    figure("fig-05-fabric-undrained-loops-" + fabric + ".png", lc,
           "Loops of cycles 1, 10 and the last, " + fabric + " fabric, isotropic consolidation (paper Fig. 5b).", {n});
  }
  const int fc = failureCycle(a);
  figure("fig-06a-fabric-undrained-gsec.png", g,
         "G_sec per cycle for both fabrics (paper Fig. 6a)" +
             (fc > 0 ? "; the anisotropic fabric fails at cycle " + std::to_string(fc) + " by our criterion." : "."),
         {iso, aniso});
  figure("fig-06b-fabric-undrained-z.png", z, "Z at the end of each cycle for both fabrics (paper Fig. 6b).", {iso, aniso});
  figure("fig-06c-fabric-undrained-du.png", du,
         "Δu against cycles for both fabrics (the paper discusses it with Fig. 6: no sharp rise of Δu at failure).",
         {iso, aniso});
}

void Writer::drainedSection() {
  m_md += "## 4. Drained cycles (paper Figures 7–10)\n\n";
  Table t{{"run", "G_sec cycle 1", "G_sec last", "change", "Z cycle 1", "Z last", "change", "Z trend (paper)", "ε_v end of last cycle",
           "q min", "q max"}, {}};
  std::vector<std::pair<std::string, std::string>> drained;  // (folder, label)
  for (const History& h : kHistories)
    drained.push_back({runName("isotropic", h.key, "drained"), std::string("isotropic fabric, ") + h.label});
  drained.push_back({runName("anisotropic", "isotropic", "drained"), "anisotropic fabric, isotropic consolidation"});
  for (std::size_t i = 0; i < drained.size(); ++i) {
    const RunData& r = run(drained[i].first);
    const std::string paperZ = i < 3 ? kHistories[i].paperZ : "no sharp change (Fig. 9b)";
    if (!r.present()) {
      t.rows.push_back({drained[i].second, "not run", "", "", "", "", "", paperZ, "", "", ""});
      continue;
    }
    const Change g = change(r, "G_sec_Pa"), z = change(r, "Z_end");
    const auto rows = cyclicRows(r);
    const std::vector<double> q = pick(r, "q_Pa", rows, 1.0);
    t.rows.push_back({drained[i].second, MPa(g.first), MPa(g.last), pct(g.percent), fmt(z.first, 3), fmt(z.last, 3),
                      pct(z.percent), zTrend(r) + " (" + paperZ + ")", fmtE(lastOf(cycleColumn(r, "eps_v_end"))),
                      kPa(minOf(q)), kPa(maxOf(q))});
  }
  m_md += t.str();
  m_md += "ε_v is compression-positive. The paper notes a much larger extension (negative q) for the isotropically "
          "consolidated specimen than for the over-consolidated one (Fig. 7a vs 7c; " + std::string(kSecDrCons) +
          "), compressive ε_v where the undrained Δu is positive (Fig. 8), Z trends as in undrained (Fig. 9a), no sharp "
          "change of Z for the anisotropic fabric (Fig. 9b; " + kSecDrDep + ").\n\n";

  std::vector<std::string> histNeeds;
  for (int i = 0; i < 3; ++i) histNeeds.push_back(drained[static_cast<std::size_t>(i)].first);
  charts::Chart sp{"Drained stress paths, isotropic fabric (paper Fig. 7a–c)", "p′ (kPa)", "q = σ′v − σ′h (kPa)", false,
                   false, {}, 900, 600};
  charts::Chart ev{"Volumetric strain, drained, isotropic fabric (paper Fig. 8a–c)", "cycles", "ε_v (−, compression +)",
                   false, false, {}, 900, 600};
  charts::Chart tau{"Shear stress, drained, isotropic fabric (paper Fig. 8d–f)", "cycles", "τ (kPa)", false, false, {}, 900, 600};
  charts::Chart z{"Coordination number, drained, isotropic fabric (paper Fig. 9a)", "cycle", "Z at cycle end (−)", false,
                  false, {}, 900, 600};
  for (int i = 0; i < 3; ++i) {
    const auto& [n, label] = drained[static_cast<std::size_t>(i)];
    if (!has(n)) continue;
    const char* hl = kHistories[i].label;
    sp.series.push_back(stressPath(run(n), hl, true));
    ev.series.push_back(againstCycles(run(n), "eps_v", 1.0, hl));
    tau.series.push_back(againstCycles(run(n), "tau_Pa", 1e-3, hl));
    z.series.push_back(perCycle(run(n), "Z_end", 1.0, hl));
  }
  figure("fig-07-drained-stress-paths.png", sp, "Drained q–p′ paths for the three histories (paper Fig. 7a–c).", histNeeds);
  for (int i = 0; i < 3; ++i) {
    const std::string& n = drained[static_cast<std::size_t>(i)].first;
    charts::Chart lc{std::string("τ–γ loops, drained, ") + kHistories[i].label + " (paper Fig. 7" + kHistories[i].loopPanel + ")",
                     "shear strain γ (−)", "τ (kPa)", false, false, {}, 900, 600};
    if (has(n))
      for (int c : loopCycles(run(n))) lc.series.push_back(loop(run(n), c, "cycle " + std::to_string(c)));
    figure(std::string("fig-07-drained-loops-") + kHistories[i].key + ".png", lc,
           std::string("Drained loops of cycles 1, 10 and the last, ") + kHistories[i].label + " (paper Fig. 7" + kHistories[i].loopPanel + ").",
           {n});
  }
  figure("fig-08-drained-epsv.png", ev, "Volumetric strain against cycles for the three histories (paper Fig. 8a–c).", histNeeds);
  figure("fig-08-drained-tau.png", tau, "τ against cycles, drained (paper Fig. 8d–f).", histNeeds);
  figure("fig-09a-drained-z.png", z, "Z per cycle, drained, three histories (paper Fig. 9a).", histNeeds);

  const std::string isoD = drained[0].first, anisoD = drained[3].first;
  charts::Chart zf{"Coordination number, drained, isotropic consolidation (paper Fig. 9b)", "cycle", "Z at cycle end (−)",
                   false, false, {}, 900, 600};
  charts::Chart gd{"Secant shear stiffness, drained (not shown in the paper)", "cycle", "G_sec (MPa)", false, false, {}, 900, 600};
  charts::Chart spf{"Drained stress paths, isotropic consolidation (paper Fig. 10)", "p′ (kPa)", "q = σ′v − σ′h (kPa)", false,
                    false, {}, 900, 600};
  for (const auto& [n, label] : drained)
    if (has(n)) gd.series.push_back(perCycle(run(n), "G_sec_Pa", 1e-6, label));
  for (const auto& [fabric, n] : {std::pair<std::string, std::string>{"isotropic", isoD}, {"anisotropic", anisoD}})
    if (has(n)) {
      zf.series.push_back(perCycle(run(n), "Z_end", 1.0, fabric + " fabric"));
      spf.series.push_back(stressPath(run(n), fabric + " fabric", true));
    }
  figure("fig-09b-fabric-drained-z.png", zf, "Z per cycle, drained, isotropic and anisotropic fabric (paper Fig. 9b).",
         {isoD, anisoD});
  std::vector<std::string> allD;
  for (const auto& d : drained) allD.push_back(d.first);
  figure("fig-09c-drained-gsec.png", gd,
         "G_sec per cycle of the four drained runs (the paper says they resemble Fig. 4 and does not show them; § Drained "
         "cyclic loading).",
         allD);
  figure("fig-10-fabric-drained-stress-paths.png", spf,
         "Drained q–p′ paths for both fabrics (paper Fig. 10: no excursion to the extension side for the anisotropic "
         "fabric).",
         {isoD, anisoD});
  for (const auto& [fabric, n] : {std::pair<std::string, std::string>{"isotropic", isoD}, {"anisotropic", anisoD}}) {
    charts::Chart lc{"τ–γ loops, drained, " + fabric + " fabric (paper Fig. 10)", "shear strain γ (−)", "τ (kPa)", false,
                     false, {}, 900, 600};
    if (has(n))
      for (int c : loopCycles(run(n))) lc.series.push_back(loop(run(n), c, "cycle " + std::to_string(c)));
    figure("fig-10-fabric-drained-loops-" + fabric + ".png", lc,
           "Drained loops of cycles 1, 10 and the last, " + fabric + " fabric (paper Fig. 10).", {n});
  }
}

void Writer::consistencySection() {
  m_md += "## 5. Drained against undrained\n\n";
  m_md += "The paper finds drained stiffness \"similar\" to the undrained one (" + std::string(kSecDrCons) +
          "), Z trends alike (Fig. 9a vs 4b), and positive Δu where the drained specimen compresses (Fig. 8 vs 3). "
          "Signs use ±" + fmt(kDuTolerance / 1e3, 1) + " kPa for Δu and ±" + fmtE(kEpsTolerance) + " for ε_v as zero.\n\n";
  Table t{{"fabric, history", "G_sec,1 drained", "G_sec,1 undrained", "drained / undrained", "Δu end, last cycle (U)",
           "ε_v end, last cycle (D)", "signs agree", "Z trend D", "Z trend U"}, {}};
  for (const auto& [fabric, hist] : {std::pair<const char*, const char*>{"isotropic", "isotropic"}, {"isotropic", "k0"},
                                     {"isotropic", "ocr"}, {"anisotropic", "isotropic"}}) {
    const RunData& u = run(runName(fabric, hist, "undrained"));
    const RunData& d = run(runName(fabric, hist, "drained"));
    const double gd = change(d, "G_sec_Pa").first, gu = change(u, "G_sec_Pa").first;
    const double du = lastOf(cycleColumn(u, "du_end_Pa")), ev = lastOf(cycleColumn(d, "eps_v_end"));
    const char su = signOf(du, kDuTolerance), sd = signOf(ev, kEpsTolerance);
    std::string label = std::string(fabric) + ", ";
    for (const History& h : kHistories)
      if (std::string(hist) == h.key) label += h.label;
    t.rows.push_back({label, d.present() ? MPa(gd) : "not run", u.present() ? MPa(gu) : "not run", fmt(gd / gu, 2),
                      kPa(du), fmtE(ev), su == '?' || sd == '?' ? "—" : su == sd ? "yes" : "no",
                      d.present() ? zTrend(d) : "—", u.present() ? zTrend(u) : "—"});
  }
  m_md += t.str();
}

void Writer::inertialSection() {
  m_md += "## 6. Inertial number of each run\n\n";
  m_md += "The paper's simulations are quasi-static but it gives no inertial number. Ours is I = ε̇ d̄ √(ρ/p′) over the "
          "cyclic stage (median and maximum of the samples of `timeseries.csv`); the threshold is the scene's "
          "`guards.warn_inertial_number`.\n\n";
  Table t{{"run", "median I", "max I", "threshold", "quasi-static (max ≤ threshold)", "warnings"}, {}};
  std::vector<std::string> names;
  for (const std::string& f : studyFolders())
    if (f.rfind("run-", 0) == 0) names.push_back(f);
  for (const std::string& f : optionalStudyFolders()) names.push_back(f);
  for (const std::string& f : names) {
    const RunData& r = run(f);
    if (!r.present()) {
      if (std::find(optionalStudyFolders().begin(), optionalStudyFolders().end(), f) == optionalStudyFolders().end())
        t.rows.push_back({code(f), "not run", "", "", "", ""});
      continue;
    }
    const MedianMax mm = cyclicMedianMax(r, "inertial_number");
    t.rows.push_back({code(f), fmtE(mm.median), fmtE(mm.max), fmtE(r.warnInertialNumber),
                      !std::isfinite(mm.max) ? "—" : mm.max <= r.warnInertialNumber ? "yes" : "no",
                      std::to_string(r.warnings)});
  }
  m_md += t.str();
}

void Writer::contactLawSection() {
  const std::vector<std::string>& md = optionalStudyFolders();
  bool any = false;
  for (const std::string& f : md) any = any || has(f);
  if (!any) return;
  m_md += "## 7. Contact laws: default against Mindlin–Deresiewicz (issue 9)\n\n";
  m_md += "The same undrained runs (isotropic consolidation) with the default tangential law and with the "
          "Mindlin–Deresiewicz law (folders `*-md`). Damping ratio D = W_loop / (4π W_el) per cycle.\n\n";
  Table t{{"fabric", "contact law", "G_sec cycle 1", "G_sec last", "D cycle 1", "D last", "Δu end, last cycle",
           "failure cycle", "median I"}, {}};
  struct Pair {
    std::string fabric, hm, md;
  };
  const std::vector<Pair> pairs = {{"isotropic", runName("isotropic", "isotropic", "undrained"), md[0]},
                                   {"anisotropic", runName("anisotropic", "isotropic", "undrained"), md[1]}};
  charts::Chart d{"Damping ratio per cycle: contact laws", "cycle", "damping ratio D (−)", false, false, {}, 900, 600};
  charts::Chart g{"Secant shear stiffness per cycle: contact laws", "cycle", "G_sec (MPa)", false, false, {}, 900, 600};
  charts::Chart du{"Excess pore pressure at the end of each cycle: contact laws", "cycle", "Δu at cycle end (kPa)", false,
                   false, {}, 900, 600};
  for (const Pair& p : pairs) {
    for (const auto& [n, law] : {std::pair<std::string, std::string>{p.hm, "default"}, {p.md, "Mindlin–Deresiewicz"}}) {
      const RunData& r = run(n);
      if (!r.present()) {
        t.rows.push_back({p.fabric, law, "not run", "", "", "", "", "", ""});
        continue;
      }
      const Change gc = change(r, "G_sec_Pa"), dc = change(r, "damping_ratio");
      const int fc = failureCycle(r);
      t.rows.push_back({p.fabric, law, MPa(gc.first), MPa(gc.last), fmt(dc.first, 3), fmt(dc.last, 3),
                        kPa(lastOf(cycleColumn(r, "du_end_Pa"))),
                        fc > 0 ? std::to_string(fc) : "none in " + std::to_string(lastCycle(r)),
                        fmtE(cyclicMedianMax(r, "inertial_number").median)});
      const std::string label = p.fabric + " fabric, " + law;
      d.series.push_back(perCycle(r, "damping_ratio", 1.0, label));
      g.series.push_back(perCycle(r, "G_sec_Pa", 1e-6, label));
      du.series.push_back(perCycle(r, "du_end_Pa", 1e-3, label));
    }
  }
  m_md += t.str();
  // The runs may cover different numbers of cycles (the M–D runs are shorter): compare both laws at the last
  // cycle both reached.
  Table same{{"fabric", "cycle N (both laws)", "G_sec(N) default", "G_sec(N) M–D", "D(N) default", "D(N) M–D",
              "Δu end of N, default", "Δu end of N, M–D"}, {}};
  const auto atCycle = [](const RunData& r, const std::string& column, int cycle) {
    if (!r.hasCycles()) return kNaN;
    const auto& n = r.cycles->column("cycle");
    const auto& v = r.cycles->column(column);
    for (std::size_t k = 0; k < n.size(); ++k)
      if (static_cast<int>(n[k]) == cycle) return v[k];
    return kNaN;
  };
  for (const Pair& p : pairs) {
    if (!has(p.hm) || !has(p.md)) continue;
    const int n = std::min(lastCycle(run(p.hm)), lastCycle(run(p.md)));
    if (n < 1) continue;
    const RunData &a = run(p.hm), &b = run(p.md);
    same.rows.push_back({p.fabric, std::to_string(n), MPa(atCycle(a, "G_sec_Pa", n)), MPa(atCycle(b, "G_sec_Pa", n)),
                         fmt(atCycle(a, "damping_ratio", n), 3), fmt(atCycle(b, "damping_ratio", n), 3),
                         kPa(atCycle(a, "du_end_Pa", n)), kPa(atCycle(b, "du_end_Pa", n))});
  }
  if (!same.rows.empty()) {
    m_md += "\nBoth laws at the same cycle (the last cycle both runs reached):\n\n";
    m_md += same.str();
  }
  for (const Pair& p : pairs) {
    charts::Chart lc{"τ–γ loops, undrained, " + p.fabric + " fabric: contact laws", "shear strain γ (−)", "τ (kPa)", false,
                     false, {}, 900, 600};
    for (const auto& [n, law] : {std::pair<std::string, std::string>{p.hm, "default"}, {p.md, "M–D"}})
      if (has(n))
        for (int c : loopCycles(run(n))) lc.series.push_back(loop(run(n), c, law + ", cycle " + std::to_string(c)));
    figure("fig-md-loops-" + p.fabric + ".png", lc,
           "Loops of cycles 1, 10 and the last with both contact laws, " + p.fabric + " fabric.", {p.hm, p.md});
  }
  std::vector<std::string> all = {pairs[0].hm, pairs[0].md, pairs[1].hm, pairs[1].md};
  figure("fig-md-damping.png", d, "Damping ratio per cycle with both contact laws.", all);
  figure("fig-md-gsec.png", g, "G_sec per cycle with both contact laws.", all);
  figure("fig-md-du.png", du, "Δu at the end of each cycle with both contact laws.", all);
}

void Writer::notesSection(const std::string& notesFile) {
  if (notesFile.empty()) return;
  std::ifstream in(notesFile, std::ios::binary);
  if (!in) throw IoError(notesFile + ": cannot open the discussion notes");
  std::ostringstream s;
  s << in.rdbuf();
  m_md += "## Discussion\n\n";
  m_md += s.str();
  if (!m_md.empty() && m_md.back() != '\n') m_md += "\n";
  m_md += "\n";
}

void Writer::dataNotesSection() {
  std::vector<std::string> notes;
  for (const auto& [name, r] : m_runs)
    for (const std::string& n : r.notes) notes.push_back(n);
  if (notes.empty() && m_skipped.empty()) return;
  m_md += "## Data notes\n\n";
  for (const std::string& n : notes) m_md += "- " + n + "\n";
  for (const std::string& s : m_skipped) m_md += "- figure skipped: " + s + "\n";
  m_md += "\n";
}

ReportSummary Writer::write(const std::string& notesFile) {
  if (!notesFile.empty() && !fs::exists(notesFile)) throw IoError(notesFile + ": discussion notes file not found");
  std::error_code ec;
  fs::create_directories(m_out, ec);
  if (ec) throw IoError(m_out + ": cannot create the report folder: " + ec.message());

  m_md = "# Stress history and cyclic behaviour: FabricLab against the paper\n\n";
  m_md += "Generated by `fabriclab-report` from the study folder `" + m_study +
          "` (one results folder per scene of `resources/scenes/paper/`). The paper: *Exploring the effects of stress "
          "history on the drained and undrained cyclic behaviour of granular materials* — 4000 glass beads in a periodic "
          "cell, an isotropic and an anisotropic fabric, isotropic, K0 and over-consolidation (OCR = 4.5) to p′ = 318 kPa, "
          "100 strain-controlled cycles of ε_a = 0.023 %, drained and undrained (its Table 2: 8 runs).\n\n";
  m_md += "Conventions: stresses compression-positive, q = σ′v − σ′h (signed), τ = q/2, γ = ε_a − ε_r, ε_v "
          "compression-positive, Δu = σ′3,0 − σ′3 in the constant-volume (undrained) runs, Z = contacts per particle. "
          "Figures take the paper's figure numbers; where the paper has a grid of panels we overlay the panels' curves "
          "on one chart (one scale) or draw one chart per panel.\n\n";
  runsSection();
  summarySection();
  consolidationSection();
  undrainedHistorySection();
  undrainedFabricSection();
  drainedSection();
  consistencySection();
  inertialSection();
  contactLawSection();
  notesSection(notesFile);
  dataNotesSection();

  ReportSummary sum;
  sum.readme = (fs::path(m_out) / "README.md").string();
  writeFileAtomically(sum.readme, m_md);
  sum.figures = m_figures;
  for (const auto* list : {&studyFolders(), &optionalStudyFolders()})
    for (const std::string& f : *list) {
      if (run(f).status == RunStatus::NotRun && list == &studyFolders()) sum.notRun.push_back(f);
      if (run(f).status == RunStatus::Incomplete) sum.incomplete.push_back(f);
    }
  // Figures of an earlier report that were not written now (their runs went missing) would be stale.
  const std::set<std::string> fresh(m_figures.begin(), m_figures.end());
  for (const auto& entry : fs::directory_iterator(m_out, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.rfind("fig-", 0) == 0 && entry.path().extension() == ".png" && !fresh.count(name))
      fs::remove(entry.path(), ec);
  }
  return sum;
}

}  // namespace

const std::vector<std::string>& studyFolders() {
  static const std::vector<std::string> folders = [] {
    std::vector<std::string> f = {"specimen-isotropic",   "specimen-anisotropic", "history-isotropic-isotropic",
                                  "history-isotropic-k0", "history-isotropic-ocr", "history-anisotropic-isotropic"};
    for (const char* drainage : {"drained", "undrained"}) {
      for (const History& h : kHistories) f.push_back(runName("isotropic", h.key, drainage));
      f.push_back(runName("anisotropic", "isotropic", drainage));
    }
    return f;
  }();
  return folders;
}

const std::vector<std::string>& optionalStudyFolders() {
  static const std::vector<std::string> folders = {"run-isotropic-isotropic-undrained-md",
                                                   "run-anisotropic-isotropic-undrained-md"};
  return folders;
}

ReportSummary writePaperReport(const std::string& studyDir, const std::string& outDir, const std::string& notesFile) {
  if (!fs::is_directory(studyDir)) throw IoError(studyDir + ": study folder not found");
  Writer w(studyDir, outDir);
  w.load();
  return w.write(notesFile);
}

}  // namespace fl::report
