// The desktop lab end to end, under Xvfb: the window starts, loads a tiny scene, runs it on the worker,
// renders, plots, pauses/resumes/stops, reports a broken scene by its field, survives being closed mid-run.
#include <gtest/gtest.h>

#include <QApplication>
#include <QChartView>
#include <QComboBox>
#include <QLineEdit>
#include <QMessageBox>

#include <array>
#include <cstdio>
#include <memory>
#include <random>

#include "core/measurements.hpp"
#include "ui/assembly_view.hpp"
#include "ui/main_window.hpp"
#include "ui/plots_view.hpp"
#include "ui/rose_view.hpp"
#include "ui/scene_panel.hpp"
#include "ui/sim_worker.hpp"
#include "ui/teaching_panel.hpp"
#include "ui/vtk_render_widget.hpp"
#include "ui_test_support.hpp"

using namespace fl;
using namespace fl::ui;
using fl::ui::test::waitUntil;

namespace {

class QtEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    VtkRenderWidget::setDefaultSurfaceFormat();
    m_app = std::make_unique<QApplication>(m_argc, m_argv.data());
  }
  void TearDown() override { m_app.reset(); }

 private:
  int m_argc = 1;
  char m_arg0[32] = "main_window_test";
  std::array<char*, 2> m_argv{m_arg0, nullptr};
  std::unique_ptr<QApplication> m_app;
};
[[maybe_unused]] auto* const g_env = ::testing::AddGlobalTestEnvironment(new QtEnvironment);

RunState stateOf(const MainWindow& w) {
  auto s = w.worker().latest();
  return s ? s->status.state : RunState::Empty;
}
long stepOf(const MainWindow& w) {
  auto s = w.worker().latest();
  return s ? s->status.step : -1;
}

// A window with the tiny scene loaded and its specimen built.
std::unique_ptr<MainWindow> openTiny(bool withCycles = false) {
  auto w = std::make_unique<MainWindow>();
  w->resize(1200, 800);
  w->show();
  const std::string path = test::writeFile(withCycles ? "tiny_cyclic.json" : "tiny.json", test::tinySceneJson(withCycles));
  EXPECT_TRUE(w->openSceneFile(QString::fromStdString(path))) << w->lastError().toStdString();
  EXPECT_TRUE(waitUntil([&] { return stateOf(*w) == RunState::Ready; }));
  return w;
}

int nonBackgroundPixels(const QImage& image, QRgb background) {
  int n = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const QRgb p = image.pixel(x, y);
      if (std::abs(qRed(p) - qRed(background)) + std::abs(qGreen(p) - qGreen(background)) +
              std::abs(qBlue(p) - qBlue(background)) > 30)
        ++n;
    }
  return n;
}

}  // namespace

TEST(UiMainWindow, StartsAndListsPresets) {
  MainWindow w;
  w.setPresetDirectory(QStringLiteral(FL_SOURCE_DIR "/resources/scenes"));
  w.show();
  ASSERT_TRUE(waitUntil([&] { return w.isVisible(); }));
  EXPECT_GE(w.scenePanel()->presetCount(), 1);  // at least default.json
  EXPECT_FALSE(w.teachingPanel()->toPlainText().isEmpty());
  EXPECT_TRUE(w.teachingPanel()->toPlainText().contains("Rose diagrams"));
}

TEST(UiMainWindow, LoadsRunsRendersAndPlots) {
  auto w = openTiny();
  auto first = w->worker().latest();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->positions.size(), 200u);
  EXPECT_EQ(w->scenePanel()->stageCount(), 1);

  w->worker().run();
  ASSERT_TRUE(waitUntil([&] { return stepOf(*w) > 2000 && w->snapshotsShown() >= 3; }))
      << "worker did not advance: " << w->statusText().toStdString();
  EXPECT_TRUE(w->statusText().contains("step")) << w->statusText().toStdString();
  EXPECT_TRUE(w->statusText().contains("particle-steps/s"));

  // the 3D view draws spheres: not all background
  ASSERT_TRUE(waitUntil([&] { return w->assemblyView()->frameStats().frames > 0; }));
  const QImage image = w->assemblyView()->renderWidget()->grabImage();
  ASSERT_FALSE(image.isNull());
  const QRgb background = qRgb(31, 33, 41);  // the view's background colour
  EXPECT_GT(nonBackgroundPixels(image, background), image.width() * image.height() / 50);
  EXPECT_EQ(w->assemblyView()->shownParticles(), 200);

  // plots receive points once samples exist (every 50 steps)
  ASSERT_TRUE(waitUntil([&] { return w->plotsView()->stressPathPoints() > 5; }));
  EXPECT_GT(w->plotsView()->loopPoints(), 0);
  // roses are computed from the contacts
  ASSERT_TRUE(waitUntil([&] { return w->roseView()->rebuilds() > 0; }));
  w->worker().pause();  // the tiny protocol may also have finished by now
  ASSERT_TRUE(waitUntil([&] { return stateOf(*w) == RunState::Paused || stateOf(*w) == RunState::Finished; }));
  const auto shown = w->worker().latest();
  if (!shown->contacts.empty()) {
    const FabricMeasures f = fabricFromNormals(shown->contactNormals());
    w->roseView()->setSnapshot(shown);
    ASSERT_TRUE(waitUntil([&] { return std::abs(w->roseView()->anisotropy3D() - f.anisotropy3D) < 1e-12; }, 3000));
  }
}

TEST(UiMainWindow, PauseResumeStepAndStop) {
  auto w = openTiny();
  w->worker().run();
  ASSERT_TRUE(waitUntil([&] { return stepOf(*w) > 500; }));
  w->worker().pause();
  ASSERT_TRUE(waitUntil([&] { return stateOf(*w) == RunState::Paused; }, 3000)) << "pause took too long";
  const long paused = stepOf(*w);
  waitUntil([] { return false; }, 300);
  EXPECT_EQ(stepOf(*w), paused) << "the worker kept stepping while paused";

  w->worker().step(100);
  ASSERT_TRUE(waitUntil([&] { return stepOf(*w) >= paused + 100 && stateOf(*w) == RunState::Paused; }));
  EXPECT_EQ(stepOf(*w), paused + 100);

  w->worker().run();  // resume
  ASSERT_TRUE(waitUntil([&] { return stepOf(*w) > paused + 500; }));
  w->worker().stop();
  ASSERT_TRUE(waitUntil([&] { return stateOf(*w) == RunState::Ready; }, 3000));
  const long stopped = stepOf(*w);
  waitUntil([] { return false; }, 200);
  EXPECT_EQ(stepOf(*w), stopped);
  // after a stop, run starts the scene again from step 0
  w->worker().run();
  ASSERT_TRUE(waitUntil([&] { auto s = w->worker().latest(); return s->status.state == RunState::Running && s->status.step < stopped; }));
}

TEST(UiMainWindow, BrokenSceneShowsTheFieldAndDoesNotCrash) {
  MainWindow w;
  w.show();
  std::string text = test::tinySceneJson();
  text.replace(text.find("\"time_step_factor\": 0.3"), 23, "\"time_step_factor\": 2.0");
  const std::string path = test::writeFile("broken.json", text);
  EXPECT_FALSE(w.openSceneFile(QString::fromStdString(path)));
  EXPECT_TRUE(w.lastError().contains("time_step_factor")) << w.lastError().toStdString();
  auto* box = w.findChild<QMessageBox*>("errorBox");
  ASSERT_NE(box, nullptr);
  EXPECT_TRUE(box->text().contains("time_step_factor"));
  box->close();
  // not JSON at all
  EXPECT_FALSE(w.openSceneFile(QString::fromStdString(test::writeFile("garbage.json", "{ nope"))));
  EXPECT_EQ(w.errorCount(), 2);
  // a checkpoint that does not exist: the worker catches it and reports, no exception crosses threads
  w.restartFromCheckpoint("/nonexistent/fabriclab.ckpt");
  ASSERT_TRUE(waitUntil([&] { return w.errorCount() == 3; }));
  EXPECT_EQ(stateOf(w), RunState::Error);
  EXPECT_TRUE(w.isVisible());
}

TEST(UiMainWindow, ClosingDuringARunExitsCleanly) {
  auto w = openTiny();
  w->worker().run();
  ASSERT_TRUE(waitUntil([&] { return stepOf(*w) > 200; }));
  QElapsedTimer t;
  t.start();
  w->close();
  w.reset();  // joins the worker
  EXPECT_LT(t.elapsed(), 3000);
}

TEST(UiScenePanel, SchemaFormsAndStageEditing) {
  auto w = openTiny();
  ScenePanel* panel = w->scenePanel();
  // one schema drives the forms: a field's tooltip carries its unit, range and help
  auto* shear = panel->findChild<QLineEdit*>("material.shear_modulus");
  ASSERT_NE(shear, nullptr);
  EXPECT_TRUE(shear->toolTip().contains("Pa"));
  EXPECT_TRUE(shear->toolTip().contains("allowed"));
  EXPECT_EQ(shear->text().toDouble(), 28.688e9);

  panel->addStage("hold");
  panel->addStage("cyclic");
  ASSERT_EQ(panel->stageCount(), 3);
  auto* amplitude = panel->stageForm()->findChild<QLineEdit*>("stage:cyclic.amplitude");
  ASSERT_NE(amplitude, nullptr);
  amplitude->setText("2.3e-4");
  panel->stageForm()->findChild<QLineEdit*>("stage:cyclic.cycles")->setText("3");
  panel->moveStage(2, -1);  // cyclic before hold
  panel->removeStage(2);    // drop the hold
  Scene applied;
  QObject::connect(panel, &ScenePanel::sceneApplied, [&](const Scene& s) { applied = s; });
  ASSERT_TRUE(panel->apply()) << w->lastError().toStdString();
  ASSERT_EQ(applied.stages.size(), 2u);
  EXPECT_EQ(applied.stages[1].type, StageType::Cyclic);
  EXPECT_DOUBLE_EQ(applied.stages[1].amplitude, 2.3e-4);
  EXPECT_EQ(applied.stages[1].cycles, 3);

  // an out-of-range edit is refused with the field named
  panel->selectStage(1);
  panel->stageForm()->findChild<QLineEdit*>("stage:cyclic.amplitude")->setText("0.9");
  EXPECT_FALSE(panel->apply());
  EXPECT_TRUE(w->lastError().contains("amplitude")) << w->lastError().toStdString();

  // save and load round trip
  panel->stageForm()->findChild<QLineEdit*>("stage:cyclic.amplitude")->setText("1e-4");
  const std::string out = test::writeFile("saved.json", "");
  ASSERT_TRUE(panel->saveTo(QString::fromStdString(out)));
  const Scene back = loadScene(out);
  ASSERT_EQ(back.stages.size(), 2u);
  EXPECT_DOUBLE_EQ(back.stages[1].amplitude, 1e-4);
}

TEST(UiPlots, StayResponsiveWithHundredCyclesOfData) {
  // 100 cycles x 200 samples (5x the default density) plus a long monotonic part: 30 000 samples
  auto samples = std::make_shared<std::vector<Sample>>();
  for (int i = 0; i < 10000; ++i) {
    Sample s;
    s.p = 318e3 * i / 10000.0;
    s.q = 0.0;
    samples->push_back(s);
  }
  auto cycles = std::make_shared<std::vector<CycleRecord>>();
  for (int c = 1; c <= 100; ++c) {
    for (int k = 0; k < 200; ++k) {
      Sample s;
      s.stage = 1;
      s.cycle = c;
      const double phase = 2 * kPi * k / 200.0;
      s.gamma = 3.45e-4 * std::sin(phase);
      s.tau = 20e3 * std::sin(phase + 0.1) * (1.0 - 0.004 * c);
      s.q = 2 * s.tau;
      s.p = 318e3 * (1.0 - 0.005 * c) - 0.5 * s.q;
      s.du = 318e3 * 0.005 * c;
      samples->push_back(s);
    }
    CycleRecord r;
    r.cycle = c;
    r.Gsec = 60e6 * (1.0 - 0.003 * c);
    r.end.Z = 4.6 - 0.002 * c;
    cycles->push_back(r);
  }
  Snapshot snap;
  snap.samples = samples;
  snap.cycles = cycles;
  StageSpec compress, cyc;
  cyc.type = StageType::Cyclic;
  cyc.drainage = Drainage::Undrained;
  snap.stages = {compress, cyc};

  PlotsView plots;
  plots.resize(900, 600);
  plots.show();
  ASSERT_TRUE(waitUntil([&] { return plots.isVisible(); }));
  QElapsedTimer t;
  t.start();
  plots.redraw(snap);
  QCoreApplication::processEvents();
  const auto image = plots.stressPathView()->grab();  // includes painting the charts
  const double ms = static_cast<double>(t.nsecsElapsed()) / 1e6;
  std::printf("[ UiPlots ] %zu samples, 100 cycles: redraw %.1f ms (series update %.1f ms), "
              "points per series <= %zu\n", samples->size(), ms, plots.lastUpdateMs(), PlotsView::kMaxPointsPerSeries);
  EXPECT_LE(plots.stressPathPoints(), static_cast<int>(PlotsView::kMaxPointsPerSeries));
  EXPECT_LE(plots.loopPoints(), static_cast<int>(PlotsView::kMaxPointsPerSeries));
  EXPECT_GT(plots.loopPoints(), 1000);
  EXPECT_GT(plots.cyclePoints(), 500);  // a monotonic series decimates to fewer points
  EXPECT_EQ(plots.stiffnessPoints(), 100);
  EXPECT_LT(plots.lastUpdateMs(), 250.0);  // well under a frame budget of a 5 Hz plot refresh
  EXPECT_FALSE(image.isNull());
}

namespace {
// 4000 spheres on a jittered lattice in a 20 mm box, each touching its +x, +y and +z neighbours.
std::shared_ptr<Snapshot> syntheticAssembly(int perSide = 16) {
  auto s = std::make_shared<Snapshot>();
  const double a = 1.1e-3, L = perSide * a;
  s->cell = Vec3(L, L, L).asDiagonal();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.05, 0.05), f(0.1, 3.0);
  auto index = [&](int i, int j, int k) { return (i * perSide + j) * perSide + k; };
  for (int i = 0; i < perSide; ++i)
    for (int j = 0; j < perSide; ++j)
      for (int k = 0; k < perSide; ++k) {
        s->positions.push_back(Vec3((i + 0.5 + u(rng)) * a, (j + 0.5 + u(rng)) * a, (k + 0.5 + u(rng)) * a));
        s->radii.push_back(0.5 * a * (1.0 + u(rng)));
        s->speeds.push_back(f(rng));
        s->contactCounts.push_back(6);
        s->meanStress.push_back(1e5 * f(rng));
      }
  for (int i = 0; i < perSide; ++i)
    for (int j = 0; j < perSide; ++j)
      for (int k = 0; k < perSide; ++k) {
        const int p = index(i, j, k);
        const int next[3] = {index((i + 1) % perSide, j, k), index(i, (j + 1) % perSide, k), index(i, j, (k + 1) % perSide)};
        for (int d = 0; d < 3; ++d) {
          Vec3 b = Vec3::Zero();
          b[d] = a;
          s->contacts.push_back({p, next[d], s->positions[static_cast<std::size_t>(p)], b, f(rng)});
        }
      }
  return s;
}
}  // namespace

TEST(UiAssemblyView, FrameTimeAt4000Spheres) {
  AssemblyView view;
  view.resize(900, 700);
  view.show();
  auto snap = syntheticAssembly();
  ASSERT_EQ(snap->positions.size(), 4096u);
  auto measure = [&](const char* what, bool rebuild = true) {
    view.setSnapshot(snap);
    ASSERT_TRUE(waitUntil([&] { return view.frameStats().frames > 0; }));
    view.resetFrameStats();
    for (int k = 0; k < 10; ++k) {
      // rebuild the VTK data as for a new snapshot, then draw (or only redraw, as after a camera move)
      if (rebuild) view.setSnapshot(snap);
      else view.renderWidget()->update();
      const long before = view.frameStats().frames;
      ASSERT_TRUE(waitUntil([&] { return view.frameStats().frames > before; }));
    }
    std::printf("[ UiAssemblyView ] %s: %ld spheres, %ld force chains: frame mean %.1f ms, max %.1f ms; "
                "data build %.1f ms\n", what, view.shownParticles(), view.shownForceChains(),
                view.frameStats().meanMs(), view.frameStats().maxMs, view.lastBuildMs());
  };
  measure("spheres + chains");
  measure("spheres + chains, redraw only", false);
  EXPECT_GT(view.shownForceChains(), 1000);
  EXPECT_LT(view.shownForceChains(), static_cast<long>(snap->contacts.size()));  // threshold: above the mean
  view.setShowForceChains(false);
  measure("spheres only");
  EXPECT_EQ(view.shownForceChains(), 0);
  EXPECT_EQ(view.shownParticles(), 4096);
}
