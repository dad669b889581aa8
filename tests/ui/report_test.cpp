// The paper report (app/report_*.cpp) and the offscreen charts (ui/chart_render.cpp), in-process on a small
// synthetic study folder whose numbers are known: PNGs exist and decode at their size, the comparison table
// carries the numbers of the synthetic data (G_sec and Z trends, void ratios, OCR, K0, failure cycle, Δu
// sign, inertial number), missing runs are "not run", garbled files name file and line, unfinished last
// lines and appended re-runs are handled. Needs no display (Qt "offscreen" platform) and no VTK.
#include <gtest/gtest.h>

#include <QColor>
#include <QImage>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include <unistd.h>

#include "app/report_csv.hpp"
#include "app/report_paper.hpp"
#include "core/errors.hpp"
#include "core/run_outputs.hpp"
#include "ui/chart_render.hpp"

namespace fs = std::filesystem;
using namespace fl;

namespace {

fs::path tempRoot() {
  const fs::path d = fs::temp_directory_path() / ("fabriclab_report_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

void writeText(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> splitHeader(const std::string& h) {
  std::vector<std::string> out;
  std::stringstream s(h);
  std::string f;
  while (std::getline(s, f, ',')) out.push_back(f);
  return out;
}

// Rows in the exact column layout of RunOutputs (so the test follows the real format).
class CsvWriter {
 public:
  explicit CsvWriter(const std::string& header) : m_cols(splitHeader(header)), m_text(header + "\n") {}
  void row(const std::map<std::string, double>& values) {
    for (const auto& [k, v] : values)
      EXPECT_NE(std::find(m_cols.begin(), m_cols.end(), k), m_cols.end()) << "unknown column " << k;
    for (std::size_t i = 0; i < m_cols.size(); ++i) {
      const auto it = values.find(m_cols[i]);
      char b[64];
      std::snprintf(b, sizeof b, "%.10g", it == values.end() ? 0.0 : it->second);
      m_text += (i ? "," : "") + std::string(b);
    }
    m_text += "\n";
  }
  std::string& text() { return m_text; }

 private:
  std::vector<std::string> m_cols;
  std::string m_text;
};

Sample endSample(double p, double q, double e, double a2D, double a3D, double Z = 5.5) {
  Sample s;
  s.p = p;
  s.q = q;
  s.voidRatio = e;
  s.a2D = a2D;
  s.a3D = a3D;
  s.Z = Z;
  s.stress = Vec3(p - q / 3, p - q / 3, p + 2 * q / 3);
  return s;
}

StageSummary stage(int index, const std::string& name, const std::string& type, const Sample& end, double K0,
                   double ocr) {
  StageSummary s;
  s.index = index;
  s.name = name;
  s.type = type;
  s.steps = 1000;
  s.end = end;
  s.K0 = K0;
  s.ocr = ocr;
  return s;
}

// A specimen or consolidation folder: stages.json, a stress path, empty cycles, scene.json.
void writeHistory(const fs::path& dir, const std::vector<StageSummary>& stages,
                  const std::vector<std::pair<double, double>>& svSh, int sceneStages) {
  writeText(dir / "stages.json", stageSummariesJson("synthetic", stages));
  CsvWriter ts(RunOutputs::timeSeriesHeader());
  long step = 0;
  for (const auto& [sv, sh] : svSh)
    ts.row({{"step", static_cast<double>(step += 100)},
            {"sxx_Pa", sh},
            {"syy_Pa", sh},
            {"szz_Pa", sv},
            {"p_Pa", (sv + 2 * sh) / 3},
            {"q_Pa", sv - sh},
            {"void_ratio", 0.55},
            {"inertial_number", 1e-4}});
  writeText(dir / "timeseries.csv", ts.text());
  writeText(dir / "cycles.csv", RunOutputs::cycleHeader() + "\n");
  std::string sc = R"({"stages": [)";
  for (int i = 0; i < sceneStages; ++i) sc += std::string(i ? "," : "") + R"({"type": "k0"})";
  writeText(dir / "scene.json", sc + "]}\n");
  writeText(dir / "warnings.txt", "# run-time warnings\n");
}

struct RunSpec {
  std::vector<double> G, Z, duMin, duEnd, epsV;  // per cycle [Pa], [-], [Pa], [Pa], [-]
  double tauAmp = 50e3;                          // [Pa]
  int failedFrom = 0;                            // first failed cycle (0: none)
  double inertialPeak = 2e-4;                    // one sample's inertial number
  bool partialLastLine = false;
};

// A cyclic run: analytic elliptic tau-gamma loops (20 samples per cycle) and the given per-cycle records.
void writeRun(const fs::path& dir, const RunSpec& r) {
  const int n = static_cast<int>(r.G.size());
  const double A = 3.45e-4;
  CsvWriter ts(RunOutputs::timeSeriesHeader());
  long step = 0;
  for (int c = 1; c <= n; ++c)
    for (int k = c == 1 ? 0 : 1; k <= 20; ++k) {
      const double phi = 2 * std::numbers::pi * k / 20.0;
      const double gamma = A * std::sin(phi), tau = r.G[c - 1] * gamma + 5e3 * std::cos(phi) - 5e3;
      ts.row({{"step", static_cast<double>(step += 100)},
              {"time_s", (c - 1) + k / 20.0},
              {"cycle", static_cast<double>(c)},
              {"p_Pa", 318e3 - 1e3 * c + 2e3 * std::sin(phi)},
              {"q_Pa", 2 * tau},
              {"tau_Pa", tau},
              {"gamma", gamma},
              {"eps_a", 2 * gamma / 3},
              {"eps_v", r.epsV[c - 1] * k / 20.0},
              {"du_Pa", r.duEnd[c - 1] * k / 20.0},
              {"Z", r.Z[c - 1]},
              {"inertial_number", c == n && k == 10 ? r.inertialPeak : 2e-4}});
    }
  std::string tsText = ts.text();
  if (r.partialLastLine) tsText += "99999,3.1,0,4,317000,12";  // a killed run: no newline
  writeText(dir / "timeseries.csv", tsText);
  CsvWriter cy(RunOutputs::cycleHeader());
  for (int c = 1; c <= n; ++c)
    cy.row({{"cycle", static_cast<double>(c)},
            {"G_sec_Pa", r.G[c - 1]},
            {"E_sec_Pa", 2.5 * r.G[c - 1]},
            {"damping_ratio", 0.1 + 0.01 * c},
            {"tau_min_Pa", -r.tauAmp},
            {"tau_max_Pa", r.tauAmp},
            {"p_min_Pa", 300e3},
            {"p_max_Pa", 320e3},
            {"du_min_Pa", r.duMin[c - 1]},
            {"du_max_Pa", r.duEnd[c - 1] + 5e3},
            {"du_end_Pa", r.duEnd[c - 1]},
            {"gamma_min", -A},
            {"gamma_max", A},
            {"eps_v_end", r.epsV[c - 1]},
            {"Z_end", r.Z[c - 1]},
            {"failed", r.failedFrom > 0 && c >= r.failedFrom ? 1.0 : 0.0}});
  writeText(dir / "cycles.csv", cy.text());
  Sample end = endSample(310e3, 0, 0.55, 0.03, 0.02, r.Z.back());
  writeText(dir / "stages.json", stageSummariesJson("synthetic run", {stage(0, "cycles", "cyclic", end, 1.0, 1.0)}));
  writeText(dir / "scene.json",
            R"({"stages": [{"type": "cyclic", "cycles": )" + std::to_string(n) +
                R"(}], "failure": {"min_pressure_fraction": 0.2, "min_stiffness_fraction": 0.2},
                "guards": {"warn_inertial_number": 0.001}})");
  writeText(dir / "warnings.txt", "# run-time warnings\nsomething happened\n");
}

// The synthetic study. Not run: run-isotropic-ocr-drained (no folder), run-anisotropic-isotropic-drained
// (empty folder). isotropic-k0-drained was re-run into its folder (appended rows), and
// isotropic-isotropic-undrained ends in an unfinished line.
fs::path buildStudy(const std::string& name, bool withMd = false) {
  const fs::path s = tempRoot() / name;
  fs::remove_all(s);
  writeHistory(s / "specimen-isotropic",
               {stage(0, "deposition", "isotropic_compression", endSample(50e3, 0, 0.600, 0.021, 0.011), 1.0, 1.0)},
               {{10e3, 10e3}, {50e3, 50e3}}, 1);
  writeHistory(s / "specimen-anisotropic",
               {stage(0, "prestrain: pre-strain", "triaxial", endSample(70e3, 50e3, 0.650, 0.300, 0.250), 0.5, 1.1),
                stage(1, "prestrain: re-consolidation", "isotropic_compression", endSample(50e3, 0, 0.640, 0.200, 0.150),
                      1.0, 2.3)},
               {{50e3, 50e3}, {100e3, 50e3}, {50e3, 50e3}}, 1);
  writeHistory(s / "history-isotropic-isotropic",
               {stage(0, "consolidation", "isotropic_compression", endSample(318e3, 0, 0.550, 0.020, 0.010), 1.0, 1.0)},
               {{50e3, 50e3}, {200e3, 200e3}, {318e3, 318e3}}, 1);
  writeHistory(s / "history-isotropic-k0",
               {stage(0, "consolidation", "k0", endSample(318e3, 150e3, 0.551, 0.060, 0.040), 0.450, 1.0)},
               {{50e3, 50e3}, {200e3, 100e3}, {418e3, 268e3}}, 1);
  writeHistory(s / "history-isotropic-ocr",
               {stage(0, "K0 loading", "k0", endSample(800e3, 860e3, 0.549, 0.070, 0.050), 0.400, 1.0),
                stage(1, "K0 unloading", "k0", endSample(350e3, 0, 0.552, 0.030, 0.012), 1.0, 4.1),
                stage(2, "adjust", "isotropic_compression", endSample(318e3, 0, 0.552, 0.030, 0.012), 1.0, 4.5)},
               {{50e3, 50e3}, {500e3, 200e3}, {1431e3, 572e3}, {800e3, 560e3}, {330e3, 330e3}, {318e3, 318e3}}, 3);
  writeHistory(s / "history-anisotropic-isotropic",
               {stage(0, "consolidation", "isotropic_compression", endSample(318e3, 0, 0.585, 0.190, 0.140), 1.0, 1.0)},
               {{50e3, 50e3}, {318e3, 318e3}}, 1);

  RunSpec isoU{{100e6, 95e6, 90e6}, {5.60, 5.55, 5.50}, {-5e3, -4e3, -3e3}, {5e3, 10e3, 20e3}, {0, 0, 0}};
  isoU.tauAmp = 50e3;
  isoU.partialLastLine = true;
  writeRun(s / "run-isotropic-isotropic-undrained", isoU);
  RunSpec k0U{{80e6, 84e6, 88e6}, {5.40, 5.45, 5.50}, {-2e3, -1e3, 0}, {2e3, 5e3, 10e3}, {0, 0, 0}};
  k0U.tauAmp = 52e3;
  writeRun(s / "run-isotropic-k0-undrained", k0U);
  RunSpec ocrU{{70e6, 70.1e6, 70.2e6}, {5.30, 5.31, 5.32}, {0, 1e3, 2e3}, {5e3, 10e3, 15e3}, {0, 0, 0}};
  ocrU.tauAmp = 48e3;
  writeRun(s / "run-isotropic-ocr-undrained", ocrU);
  RunSpec anisoU{{40e6, 30e6, 5e6}, {4.80, 4.70, 4.30}, {-1e3, 0, 0}, {20e3, 35e3, 50e3}, {0, 0, 0}};
  anisoU.failedFrom = 3;
  anisoU.inertialPeak = 1.5e-3;
  writeRun(s / "run-anisotropic-isotropic-undrained", anisoU);
  writeRun(s / "run-isotropic-isotropic-drained",
           {{110e6, 100e6, 99e6}, {5.60, 5.55, 5.50}, {0, 0, 0}, {0, 0, 0}, {0.5e-4, 0.8e-4, 1e-4}});
  writeRun(s / "run-isotropic-k0-drained", {{90e6, 91e6, 92e6}, {5.40, 5.40, 5.40}, {0, 0, 0}, {0, 0, 0}, {0, -0.5e-4, -1e-4}});
  {  // an earlier, interrupted run of the same scene was written first into the same files
    const fs::path d = s / "run-isotropic-k0-drained";
    CsvWriter old(RunOutputs::cycleHeader());
    old.row({{"cycle", 1}, {"G_sec_Pa", 500e6}, {"Z_end", 9}});
    old.row({{"cycle", 2}, {"G_sec_Pa", 500e6}, {"Z_end", 9}});
    const std::string fresh = readText(d / "cycles.csv");
    writeText(d / "cycles.csv", old.text() + fresh.substr(fresh.find('\n') + 1));
  }
  fs::create_directories(s / "run-anisotropic-isotropic-drained");  // created, never written
  if (withMd) {
    writeRun(s / "run-isotropic-isotropic-undrained-md",
             {{120e6, 118e6, 116e6}, {5.60, 5.58, 5.56}, {-3e3, -2e3, -1e3}, {4e3, 8e3, 12e3}, {0, 0, 0}});
    writeRun(s / "run-anisotropic-isotropic-undrained-md",
             {{45e6, 40e6, 35e6}, {4.80, 4.75, 4.70}, {-1e3, 0, 0}, {15e3, 25e3, 35e3}, {0, 0, 0}});
  }
  return s;
}

// The Markdown table row whose first cell is `first` ("" if none).
std::string rowStarting(const std::string& md, const std::string& first) {
  const std::string key = "| " + first + " |";
  const auto at = md.find(key);
  if (at == std::string::npos) return "";
  return md.substr(at, md.find('\n', at) - at);
}

// Pixels within `tol` of a colour (the curves are antialiased).
int pixelsNear(const QImage& img, QColor c, int tol = 40) {
  int n = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const QColor p = img.pixelColor(x, y);
      if (std::abs(p.red() - c.red()) + std::abs(p.green() - c.green()) + std::abs(p.blue() - c.blue()) < tol) ++n;
    }
  return n;
}

// Removes the temporary folders when the tests end.
class TempCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(tempRoot(), ec);
  }
};
[[maybe_unused]] ::testing::Environment* const kCleanup = ::testing::AddGlobalTestEnvironment(new TempCleanup);

class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override { charts::ensureApplication(); }
};

}  // namespace

// ---- charts -----------------------------------------------------------------------------------------------

TEST_F(ReportTest, ChartRendersPngOfTheRequestedSizeWithTheCurveDrawn) {
  charts::Chart c{"a line", "x (-)", "y (-)", false, false, {}, 640, 480};
  charts::Series s{"sine", {}, {}, false};
  for (int i = 0; i <= 200; ++i) {
    s.x.push_back(i / 20.0);
    s.y.push_back(std::sin(i / 20.0));
  }
  c.series.push_back(s);
  const fs::path png = tempRoot() / "chart-line.png";
  charts::renderPng(c, png.string());
  QImage img(QString::fromStdString(png.string()));
  ASSERT_FALSE(img.isNull());
  EXPECT_EQ(img.width(), 640);
  EXPECT_EQ(img.height(), 480);
  EXPECT_GT(pixelsNear(img, QColor(0, 114, 178)), 300);  // the first series' colour: the curve is there
  // no temporary file left beside it
  for (const auto& e : fs::directory_iterator(png.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();

  // markers and log axes (non-positive points on a log axis are skipped, not fatal)
  charts::Chart m{"markers, log-log", "x", "y", true, true, {{"pts", {0.0, 1.0, 10.0, 100.0}, {1.0, 2.0, 20.0, -1.0}, true}}, 300, 200};
  charts::renderPng(m, (tempRoot() / "chart-log.png").string());
  EXPECT_EQ(QImage(QString::fromStdString((tempRoot() / "chart-log.png").string())).size(), QSize(300, 200));
}

TEST_F(ReportTest, ChartErrorsNameThePath) {
  charts::Chart c{"x", "x", "y", false, false, {{"s", {0, 1}, {0, 1}, false}}, 300, 200};
  const std::string bad = (tempRoot() / "no-such-dir" / "chart.png").string();
  try {
    charts::renderPng(c, bad);
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

TEST_F(ReportTest, DecimationKeepsLoopTipsAndLongLoopsRenderFast) {
  // 100 cycles x 400 samples of a tau-gamma loop
  std::vector<double> g, t;
  for (int i = 0; i < 40000; ++i) {
    const double phi = 2 * std::numbers::pi * i / 400.0;
    g.push_back(3.45e-4 * std::sin(phi) * (1 + 1e-6 * i));
    t.push_back(60e3 * std::sin(phi + 0.3));
  }
  const auto keep = charts::decimateCurve(g, t, charts::kMaxPointsPerSeries);
  EXPECT_LE(keep.size(), charts::kMaxPointsPerSeries);
  EXPECT_EQ(keep.front(), 0u);
  EXPECT_EQ(keep.back(), g.size() - 1);
  const auto iMax = static_cast<std::size_t>(std::max_element(g.begin(), g.end()) - g.begin());
  const auto iMin = static_cast<std::size_t>(std::min_element(t.begin(), t.end()) - t.begin());
  EXPECT_TRUE(std::binary_search(keep.begin(), keep.end(), iMax)) << "largest gamma dropped";
  EXPECT_TRUE(std::binary_search(keep.begin(), keep.end(), iMin)) << "smallest tau dropped";
  EXPECT_TRUE(std::is_sorted(keep.begin(), keep.end()));

  charts::Chart c{"loops", "gamma", "tau", false, false, {{"100 cycles", g, t, false}}, 900, 600};
  const auto t0 = std::chrono::steady_clock::now();
  charts::renderPng(c, (tempRoot() / "loops.png").string());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 5.0);
}

// ---- CSV reader -----------------------------------------------------------------------------------------

TEST_F(ReportTest, CsvReaderDropsAnUnfinishedLastLineAndNamesFileLineColumn) {
  const report::CsvTable t = report::parseCsv("a,b\n1,2\n3,4\n5,", "x.csv", {"a"});
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_TRUE(t.droppedPartialLine);
  EXPECT_DOUBLE_EQ(t.column("b")[1], 4.0);
  try {
    report::parseCsv("a,b\n1,2\n3,x4\n", "x.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "x.csv:3: column 2 ('b'): expected a number, got 'x4'");
  }
  try {
    report::parseCsv("a,b\n1,2,3\n", "x.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "x.csv:2: 3 fields, but the header has 2");
  }
  EXPECT_THROW(report::parseCsv("a,b\n", "x.csv", {"c"}), InputError);
  EXPECT_THROW(report::parseCsv("", "x.csv"), InputError);
  EXPECT_THROW(report::readCsv((tempRoot() / "absent.csv").string()), IoError);
}

// ---- the report ------------------------------------------------------------------------------------------

TEST_F(ReportTest, WritesFiguresAndTheComparisonTableFromTheData) {
  const fs::path study = buildStudy("study");
  const fs::path out = tempRoot() / "report";
  fs::remove_all(out);
  writeText(out / "fig-99-stale.png", "old");  // from an earlier report: must go
  const fs::path notes = tempRoot() / "notes.md";
  writeText(notes, "Our runs are looser than the paper's: *see* e.\n\n| a | b |\n|---|---|\n| 1 | 2 |\n");

  const report::ReportSummary sum = report::writePaperReport(study.string(), out.string(), notes.string());
  const std::string md = readText(out / "README.md");
  ASSERT_FALSE(md.empty());

  // figures: present ones decode at 900 x 600, those of missing runs are skipped
  for (const char* f : {"fig-01-consolidation-q-p.png", "fig-01-consolidation-sv-sh.png", "fig-02-undrained-stress-paths.png",
                        "fig-02-undrained-loops-isotropic.png", "fig-03-undrained-du.png", "fig-04a-undrained-gsec.png",
                        "fig-04b-undrained-z.png", "fig-06a-fabric-undrained-gsec.png", "fig-07-drained-loops-k0.png",
                        "fig-08-drained-epsv.png", "fig-09c-drained-gsec.png"}) {
    QImage img(QString::fromStdString((out / f).string()));
    ASSERT_FALSE(img.isNull()) << f;
    EXPECT_EQ(img.size(), QSize(900, 600)) << f;
    EXPECT_NE(md.find(std::string("](") + f + ")"), std::string::npos) << f << " not linked";
    EXPECT_NE(std::find(sum.figures.begin(), sum.figures.end(), f), sum.figures.end()) << f;
  }
  // analytic loops: the loop figure shows three curves in the palette's first three colours
  const QImage loops(QString::fromStdString((out / "fig-02-undrained-loops-isotropic.png").string()));
  EXPECT_GT(pixelsNear(loops, QColor(0, 114, 178)), 200);
  EXPECT_GT(pixelsNear(loops, QColor(213, 94, 0)), 200);
  EXPECT_FALSE(fs::exists(out / "fig-07-drained-loops-ocr.png"));
  EXPECT_FALSE(fs::exists(out / "fig-10-fabric-drained-loops-anisotropic.png"));
  EXPECT_NE(md.find("`fig-07-drained-loops-ocr.png` skipped (not run: run-isotropic-ocr-drained)"), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "fig-99-stale.png"));
  EXPECT_FALSE(fs::exists(out / "fig-md-damping.png"));  // no M-D runs: no contact-law section
  EXPECT_EQ(md.find("Contact laws"), std::string::npos);

  // missing runs: "not run" (no folder, and an empty folder)
  EXPECT_NE(rowStarting(md, "`run-isotropic-ocr-drained`").find("| not run |"), std::string::npos) << md;
  EXPECT_NE(rowStarting(md, "`run-anisotropic-isotropic-drained`").find("| not run |"), std::string::npos);
  EXPECT_EQ(sum.notRun, (std::vector<std::string>{"run-isotropic-ocr-drained", "run-anisotropic-isotropic-drained"}));
  EXPECT_NE(rowStarting(md, "`run-isotropic-k0-undrained`").find("| complete |"), std::string::npos);

  // the comparison table carries the synthetic numbers
  EXPECT_EQ(rowStarting(md, "G_sec trend, undrained, isotropic consolidation"),
            "| G_sec trend, undrained, isotropic consolidation | degrades | Fig. 4a; § Undrained cyclic loading: effect of "
            "consolidation history | -10.0 % (degrades) | same |");
  EXPECT_NE(rowStarting(md, "G_sec trend, undrained, K0 consolidation").find("| +10.0 % (hardens) | same |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "G_sec trend, undrained, OCR = 4.5").find("| +0.3 % (flat) | differs |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "Z trend, undrained, isotropic consolidation").find("| -1.8 % (decreases) | same |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "Z trend, undrained, K0 consolidation").find("| +1.9 % (increases) | same |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "Z trend, drained, K0 consolidation").find("| +0.0 % (flat) | differs |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "Z trend, drained, OCR = 4.5").find("| not run | — |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "void ratio e before cycling, isotropic fabric (p′ = 318 kPa)")
                .find("| isotropic 0.550 · k0 0.551 · ocr 0.552 | +0.022 · +0.023 · +0.024 |"),
            std::string::npos);
  EXPECT_NE(rowStarting(md, "void ratio e before cycling, anisotropic fabric").find("| 0.553 | § Simulation approach | 0.585 | +0.032 |"),
            std::string::npos);
  EXPECT_NE(rowStarting(md, "fabric anisotropy a, anisotropic specimen").find("a_2D_RB 0.200 at 50 kPa, 0.190 at 318 kPa (a_3D 0.150, 0.140)"),
            std::string::npos);
  EXPECT_NE(rowStarting(md, "over-consolidation ratio OCR = σ′v,max / σ′v").find("| 4.50 | +0.00 |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "K0 = σ′h/σ′v after K0 loading").find("K0 history 0.450 · OCR history 0.400"), std::string::npos);
  EXPECT_NE(rowStarting(md, "failure cycle, anisotropic fabric, undrained").find("| cycle 3 (our criterion, see § 3) | -64 cycles |"),
            std::string::npos);
  EXPECT_NE(rowStarting(md, "failure of the other seven runs").find("| none of 5 | same |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "negative Δu during cycling, isotropic consolidation").find("| yes: min Δu = -5.0 kPa | same |"),
            std::string::npos);
  EXPECT_NE(rowStarting(md, "negative Δu during cycling, OCR = 4.5").find("| no: min Δu = 0.0 kPa | same |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "τ amplitude (last cycle) independent of consolidation history")
                .find("50.0 kPa · 52.0 kPa · 48.0 kPa; spread 8.0 %"),
            std::string::npos);
  EXPECT_NE(rowStarting(md, "G_sec,1 anisotropic / isotropic fabric, undrained").find("| 0.40 | same |"), std::string::npos);
  // drained/undrained: isotropic pair consistent (+, +), K0 pair not (Δu +, ε_v −)
  EXPECT_NE(md.find("| 1 of 2 pairs | differs |"), std::string::npos);
  EXPECT_NE(rowStarting(md, "isotropic, K0 consolidation").find("| 90.0 MPa | 80.0 MPa | 1.12 | 10.0 kPa | -1.00e-04 | no |"),
            std::string::npos);
  // re-run appended into the same folder: the latest rows are used (G 90 -> 92, not 500)
  EXPECT_NE(rowStarting(md, "isotropic fabric, K0 consolidation").find("| 90.0 MPa | 92.0 MPa | +2.2 % |"), std::string::npos);
  EXPECT_NE(md.find("run-isotropic-k0-drained/cycles.csv: 2 rows superseded"), std::string::npos);
  // unfinished last line of a killed run: ignored and said so
  EXPECT_NE(md.find("run-isotropic-isotropic-undrained/timeseries.csv: ignored an unfinished last line"), std::string::npos);
  // inertial numbers
  EXPECT_NE(md.find("| `run-isotropic-k0-undrained` | 2.00e-04 | 2.00e-04 | 1.00e-03 | yes | 1 |"), std::string::npos);
  EXPECT_NE(md.find("| `run-anisotropic-isotropic-undrained` | 2.00e-04 | 1.50e-03 | 1.00e-03 | no | 1 |"), std::string::npos);
  // consolidation: sigma'_v,max of the OCR history from its time series
  EXPECT_NE(md.find("K0 loading to σ′v,max = 1431.0 kPa (K0 = 0.400"), std::string::npos);
  // notes verbatim as the discussion
  EXPECT_NE(md.find("## Discussion\n\n" + readText(notes)), std::string::npos);
}

TEST_F(ReportTest, ContactLawSectionWhenTheMindlinDeresiewiczRunsExist) {
  const fs::path study = buildStudy("study-md", true);
  const fs::path out = tempRoot() / "report-md";
  fs::remove_all(out);
  report::writePaperReport(study.string(), out.string(), "");
  const std::string md = readText(out / "README.md");
  EXPECT_NE(md.find("## 7. Contact laws"), std::string::npos);
  for (const char* f : {"fig-md-loops-isotropic.png", "fig-md-loops-anisotropic.png", "fig-md-damping.png",
                        "fig-md-gsec.png", "fig-md-du.png"})
    EXPECT_EQ(QImage(QString::fromStdString((out / f).string())).size(), QSize(900, 600)) << f;
  EXPECT_NE(md.find("| isotropic | Mindlin–Deresiewicz | 120.0 MPa | 116.0 MPa | 0.110 | 0.130 | 12.0 kPa | none in 3 |"),
            std::string::npos);
  EXPECT_NE(md.find("| anisotropic | default | 40.0 MPa | 5.0 MPa | 0.110 | 0.130 | 50.0 kPa | 3 |"), std::string::npos);
  // both laws at the last cycle both reached (here 3 for both fabrics)
  EXPECT_NE(md.find("Both laws at the same cycle"), std::string::npos);
  EXPECT_NE(md.find("| anisotropic | 3 | 5.0 MPa | 35.0 MPa |"), std::string::npos);
  EXPECT_NE(md.find("| 50.0 kPa | 35.0 kPa |"), std::string::npos);
  EXPECT_EQ(md.find("## Discussion"), std::string::npos);  // no notes given
}

TEST_F(ReportTest, GarbledOrMissingFilesGiveErrorsNamingFileAndLine) {
  const fs::path out = tempRoot() / "report-bad";
  {
    const fs::path study = buildStudy("study-garbled");
    const fs::path f = study / "run-isotropic-k0-undrained" / "cycles.csv";
    std::string text = readText(f);
    const auto line3 = text.find('\n', text.find('\n') + 1) + 1;  // line 3: cycle 2
    const auto g = text.find(',', line3) + 1;                       // its column 2, G_sec_Pa
    text.replace(g, text.find(',', g) - g, "8.4e7x");
    writeText(f, text);
    try {
      report::writePaperReport(study.string(), out.string(), "");
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), f.string() + ":3: column 2 ('G_sec_Pa'): expected a number, got '8.4e7x'");
    }
  }
  {
    const fs::path study = buildStudy("study-short-row");
    const fs::path f = study / "history-isotropic-k0" / "timeseries.csv";
    writeText(f, readText(f) + "1,2,3\n");
    try {
      report::writePaperReport(study.string(), out.string(), "");
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), f.string() + ":5: 3 fields, but the header has 30");
    }
  }
  {
    const fs::path study = buildStudy("study-bad-json");
    const fs::path f = study / "history-isotropic-ocr" / "stages.json";
    writeText(f, "{\n  \"scene\": \"x\",\n  \"stages\": [ {\"index\": 0,, } ]\n}\n");
    try {
      report::writePaperReport(study.string(), out.string(), "");
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(f.string() + ": not valid JSON", 0), 0u) << m;
      EXPECT_NE(m.find("line 3"), std::string::npos) << m;
    }
  }
  {
    const fs::path study = buildStudy("study-missing-csv");
    const fs::path f = study / "run-isotropic-ocr-undrained" / "cycles.csv";
    fs::remove(f);
    try {
      report::writePaperReport(study.string(), out.string(), "");
      FAIL() << "expected IoError";
    } catch (const IoError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(f.string() + ": missing", 0), 0u) << e.what();
    }
  }
  // a named notes file that does not exist, and a study folder that does not exist
  const fs::path study = buildStudy("study-ok");
  EXPECT_THROW(report::writePaperReport(study.string(), out.string(), (tempRoot() / "absent-notes.md").string()), IoError);
  EXPECT_THROW(report::writePaperReport((tempRoot() / "no-study").string(), out.string(), ""), IoError);
}

TEST_F(ReportTest, AnEmptyStudyListsEveryRunAsNotRunWithoutCrashing) {
  const fs::path study = tempRoot() / "study-empty";
  fs::remove_all(study);
  fs::create_directories(study);
  const fs::path out = tempRoot() / "report-empty";
  fs::remove_all(out);
  const report::ReportSummary sum = report::writePaperReport(study.string(), out.string(), "");
  EXPECT_EQ(sum.notRun.size(), report::studyFolders().size());
  EXPECT_TRUE(sum.figures.empty());
  const std::string md = readText(out / "README.md");
  for (const std::string& f : report::studyFolders())
    EXPECT_NE(rowStarting(md, "`" + f + "`").find("| not run |"), std::string::npos) << f;
}
