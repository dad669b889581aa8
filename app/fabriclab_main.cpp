// fabriclab: the desktop lab, and the same engine headless.
//   fabriclab [SCENE.json]                      the window on a scene (default resources/scenes/default.json)
//   fabriclab --headless SCENE [args]           no Qt at all (works without a display): fl::app::runHeadless
//   fabriclab --screenshots DIR [SCENE] [--seconds S]
//                                               runs the scene in the window, saves PNGs of the views into
//                                               DIR and logs the measured speed and frame time
//   fabriclab --measure [SCENE] [--seconds S]   only the measurements: simulation speed headless vs with the
//                                               GUI open, 3D frame time, plot redraw time
#include <QApplication>
#include <QDir>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QThread>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "app/headless.hpp"
#include "core/runner.hpp"
#include "core/scene.hpp"
#include "ui/assembly_view.hpp"
#include "ui/main_window.hpp"
#include "ui/plots_view.hpp"
#include "ui/sim_worker.hpp"
#include "ui/vtk_render_widget.hpp"

namespace {

QString defaultScene() {
  // next to the executable's source tree (build tree use), else relative to the working directory
  const QString fromSource = QStringLiteral(FL_SOURCE_DIR "/resources/scenes/default.json");
  return QFileInfo::exists(fromSource) ? fromSource : QStringLiteral("resources/scenes/default.json");
}

void pump(int ms) {
  QElapsedTimer t;
  t.start();
  while (t.elapsed() < ms) {
    QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
    QThread::msleep(2);
  }
}

// Particle-steps per second of a plain Runner on this thread, over the first `seconds` of the scene.
double headlessSpeed(const std::string& scenePath, double seconds, long* stepsOut) {
  fl::Runner runner(fl::loadScene(scenePath));
  const double n = static_cast<double>(runner.simulation().particles().size());
  QElapsedTimer t;
  t.start();
  long steps = 0;
  while (t.nsecsElapsed() * 1e-9 < seconds) {
    const long before = runner.simulation().stepCount();
    const bool more = runner.advance(50);
    steps += runner.simulation().stepCount() - before;
    if (!more) break;
  }
  *stepsOut = steps;
  return n * static_cast<double>(steps) / (t.nsecsElapsed() * 1e-9);
}

int scripted(fl::ui::MainWindow& w, const QString& scene, const QString& shotDir, double seconds) {
  using namespace fl::ui;
  long headlessSteps = 0;
  double headless = 0;
  try {
    headless = headlessSpeed(scene.toStdString(), seconds, &headlessSteps);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fabriclab: %s\n", e.what());
    return 1;
  }
  std::printf("measure: headless  %.3g particle-steps/s (%ld steps in %.1f s)\n", headless, headlessSteps, seconds);

  w.show();
  if (!w.openSceneFile(scene)) {
    std::fprintf(stderr, "fabriclab: %s\n", w.lastError().toStdString().c_str());
    return 1;
  }
  // wait for the specimen to be built, then measure from the start of the run, like the headless run
  QElapsedTimer wait;
  wait.start();
  while (wait.elapsed() < 60000) {
    pump(20);
    auto s = w.worker().latest();
    if (s && s->status.state == RunState::Ready) break;
  }
  pump(300);
  w.worker().resetStats();
  w.assemblyView()->resetFrameStats();
  w.worker().run();
  QElapsedTimer run;
  run.start();
  while (run.elapsed() < seconds * 1000) {
    pump(50);
    auto s = w.worker().latest();
    if (s && (s->status.state == RunState::Finished || s->status.state == RunState::Error)) break;
  }
  const WorkerStats st = w.worker().stats();
  const FrameStats fs = w.assemblyView()->frameStats();
  const double gui = st.runningSeconds > 0 ? st.particleSteps / st.runningSeconds : 0.0;
  auto shown = w.shownSnapshot();
  const std::size_t n = shown ? shown->positions.size() : 0;
  std::printf("measure: with GUI  %.3g particle-steps/s (%ld steps in %.1f s) = %.0f %% of headless\n", gui,
              st.steps, st.runningSeconds, headless > 0 ? 100.0 * gui / headless : 0.0);
  std::printf("measure: 3D view   %zu spheres, %ld force chains: frame time mean %.1f ms, max %.1f ms over %ld frames;"
              " VTK data build %.1f ms per snapshot\n",
              n, w.assemblyView()->shownForceChains(), fs.meanMs(), fs.maxMs, fs.frames,
              w.assemblyView()->lastBuildMs());
  std::printf("measure: snapshots %ld published, %.2f ms each to build in the worker\n", st.snapshots,
              st.snapshots ? 1e3 * st.snapshotSeconds / static_cast<double>(st.snapshots) : 0.0);

  if (shotDir.isEmpty()) return 0;
  // for the pictures: keep going until the run ends or a time limit, so the cyclic plots have data
  QElapsedTimer more;
  more.start();
  const double limit = std::max(0.0, qEnvironmentVariable("FL_SCREENSHOT_SECONDS", "150").toDouble());
  while (more.elapsed() < limit * 1000) {
    pump(100);
    auto s = w.worker().latest();
    if (s && (s->status.state == RunState::Finished || s->status.state == RunState::Error)) break;
  }
  w.worker().pause();
  pump(500);
  if (auto s = w.shownSnapshot()) w.plotsView()->redraw(*s);
  w.assemblyView()->setTranslucentSpheres(true);  // so the force chains show in the picture
  pump(500);
  std::printf("measure: plots     redraw %.1f ms (max %.1f ms) with %d stress-path points\n",
              w.plotsView()->lastUpdateMs(), w.plotsView()->maxUpdateMs(), w.plotsView()->stressPathPoints());
  const QStringList files = w.saveScreenshots(shotDir);
  for (const QString& f : files) std::printf("screenshot: %s\n", f.toStdString().c_str());
  return files.size() >= 5 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // Headless first, before anything Qt exists: it must work with no display.
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--headless") == 0) {
      std::vector<char*> args(argv, argv + argc);
      args.erase(args.begin() + k);
      args.push_back(nullptr);
      return fl::app::runHeadless(argc - 1, args.data());
    }
  }
  QString scene, shotDir;
  bool measure = false;
  double seconds = 10.0;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--screenshots" && k + 1 < argc) shotDir = argv[++k];
    else if (a == "--measure") measure = true;
    else if (a == "--seconds" && k + 1 < argc) seconds = std::atof(argv[++k]);
    else if (a == "--help" || a == "-h") {
      std::printf("usage: fabriclab [SCENE.json]\n"
                  "       fabriclab --headless SCENE.json [options]   (see fabriclab-run --help)\n"
                  "       fabriclab --screenshots DIR [SCENE.json] [--seconds S]\n"
                  "       fabriclab --measure [SCENE.json] [--seconds S]\n");
      return 0;
    } else if (!a.empty() && a[0] != '-') scene = QString::fromLocal8Bit(argv[k]);
    else {
      std::fprintf(stderr, "fabriclab: unknown option %s (try --help)\n", argv[k]);
      return 2;
    }
  }
  if (scene.isEmpty()) scene = defaultScene();

  fl::ui::VtkRenderWidget::setDefaultSurfaceFormat();
  QApplication app(argc, argv);
  fl::ui::MainWindow window;
  window.setPresetDirectory(QStringLiteral(FL_SOURCE_DIR "/resources/scenes"));
  if (measure || !shotDir.isEmpty()) return scripted(window, scene, shotDir, seconds);
  window.show();
  window.openSceneFile(scene);  // errors are shown in the window
  return app.exec();
}
