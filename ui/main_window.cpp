#include "ui/main_window.hpp"

#include <QCloseEvent>
#include <QDir>
#include <QDockWidget>
#include <QChartView>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QStatusBar>
#include <QToolBar>

#include "ui/assembly_view.hpp"
#include "ui/plots_view.hpp"
#include "ui/reactions.hpp"
#include "ui/rose_view.hpp"
#include "ui/scene_panel.hpp"
#include "ui/sim_worker.hpp"
#include "ui/teaching_panel.hpp"
#include "ui/vtk_render_widget.hpp"

namespace fl::ui {

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), m_worker(std::make_unique<SimWorker>()) {
  setWindowTitle(tr("FabricLab"));
  m_assembly = new AssemblyView(this);
  setCentralWidget(m_assembly);

  auto dock = [this](const QString& title, QWidget* w, Qt::DockWidgetArea area) {
    auto* d = new QDockWidget(title, this);
    d->setObjectName(title);
    d->setWidget(w);
    addDockWidget(area, d);
    return d;
  };
  m_scenePanel = new ScenePanel(this);
  m_roses = new RoseView(this);
  m_plots = new PlotsView(this);
  m_teaching = new TeachingPanel(this);
  QDockWidget* sceneDock = dock(tr("Scene and protocol"), m_scenePanel, Qt::LeftDockWidgetArea);
  dock(tr("Rose diagrams"), m_roses, Qt::RightDockWidgetArea);
  dock(tr("Live plots"), m_plots, Qt::BottomDockWidgetArea);
  QDockWidget* teachDock = dock(tr("What you are seeing"), m_teaching, Qt::LeftDockWidgetArea);
  tabifyDockWidget(sceneDock, teachDock);
  sceneDock->raise();

  // actions: small reaction objects (reactions.hpp)
  QToolBar* bar = addToolBar(tr("Run"));
  bar->setObjectName("run toolbar");
  QMenu* fileMenu = menuBar()->addMenu(tr("&File"));
  QMenu* runMenu = menuBar()->addMenu(tr("&Run"));
  auto action = [&](QMenu* menu, const QString& text, const QString& tip, const QKeySequence& key) {
    auto* a = new QAction(text, this);
    a->setToolTip(tip);
    a->setStatusTip(tip);
    if (!key.isEmpty()) a->setShortcut(key);
    menu->addAction(a);
    bar->addAction(a);
    return a;
  };
  new OpenSceneReaction(action(fileMenu, tr("Open..."), tr("Open a scene file (JSON)"), QKeySequence::Open), this);
  new SaveSceneReaction(action(fileMenu, tr("Save..."), tr("Save the edited scene (all defaults written out)"),
                               QKeySequence::Save), this);
  new RestartFromCheckpointReaction(
      action(fileMenu, tr("Restart from checkpoint..."), tr("Continue a run from a checkpoint file, bit-exactly"),
             QKeySequence()), this);
  new ScreenshotReaction(action(fileMenu, tr("Screenshots..."), tr("Save PNGs of the views"), QKeySequence()), this);
  bar->addSeparator();
  new RunReaction(action(runMenu, tr("Run"), tr("Run or resume the protocol"), QKeySequence(Qt::Key_F5)), this);
  new PauseReaction(action(runMenu, tr("Pause"), tr("Pause between steps; Run resumes"), QKeySequence(Qt::Key_F6)),
                    this);
  new StepReaction(action(runMenu, tr("Step"), tr("Advance %1 steps").arg(StepReaction::stepSize()),
                          QKeySequence(Qt::Key_F7)), this);
  new StopReaction(action(runMenu, tr("Stop"), tr("End the run; Run starts the scene again from the beginning"),
                          QKeySequence(Qt::Key_F8)), this);

  m_status = new QLabel(tr("no scene"), this);
  m_status->setToolTip(tr("Stage, time step count, simulated time, cycle and simulation speed "
                          "(particle-steps per second of wall time)."));
  statusBar()->addPermanentWidget(m_status, 1);

  connect(m_scenePanel, &ScenePanel::sceneApplied, this, [this](const Scene& s) { openScene(s); });
  connect(m_scenePanel, &ScenePanel::errorRaised, this, &MainWindow::showError);
  connect(m_worker.get(), &SimWorker::snapshotReady, this, &MainWindow::onSnapshotReady, Qt::QueuedConnection);
  connect(m_worker.get(), &SimWorker::errorOccurred, this, &MainWindow::showError, Qt::QueuedConnection);
  resize(1400, 900);
}

MainWindow::~MainWindow() {
  // Join the worker before the views go: it may still be publishing.
  m_worker.reset();
}

void MainWindow::closeEvent(QCloseEvent* event) {
  m_worker->pause();
  event->accept();
}

void MainWindow::setPresetDirectory(const QString& dir) { m_scenePanel->setPresetDirectory(dir); }

bool MainWindow::openSceneFile(const QString& path) { return m_scenePanel->loadFile(path); }

void MainWindow::openScene(const Scene& scene) {
  setWindowTitle(tr("FabricLab - %1").arg(QString::fromStdString(scene.name)));
  m_assembly->resetCameraOnNextSnapshot();
  m_worker->loadScene(scene);
}

void MainWindow::restartFromCheckpoint(const QString& path) {
  m_assembly->resetCameraOnNextSnapshot();
  m_worker->loadCheckpoint(path.toStdString());
}

void MainWindow::showError(const QString& message) {
  m_lastError = message;
  ++m_errorCount;
  statusBar()->showMessage(tr("Error: %1").arg(message), 15000);
  // Non-blocking: the event loop (and the worker's snapshots) keep going while it is open.
  auto* box = new QMessageBox(QMessageBox::Warning, tr("FabricLab"), message, QMessageBox::Ok, this);
  box->setObjectName("errorBox");
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();
}

void MainWindow::onSnapshotReady() {
  std::shared_ptr<const Snapshot> s = m_worker->latest();
  if (!s || s == m_shown) return;
  m_shown = s;
  ++m_snapshotsShown;
  if (!s->positions.empty()) {
    m_assembly->setSnapshot(s);
    m_roses->setSnapshot(s);
  }
  m_plots->setSnapshot(s);
  updateStatus(*s);
}

QString MainWindow::statusText() const { return m_status->text(); }

void MainWindow::updateStatus(const Snapshot& s) {
  const RunStatus& st = s.status;
  QString text = QString("%1").arg(runStateName(st.state));
  if (!st.stageName.empty())
    text += tr("  |  stage %1/%2 '%3' (%4, %5 %)")
                .arg(st.stageIndex + 1)
                .arg(st.stageCount)
                .arg(QString::fromStdString(st.stageName))
                .arg(QString::fromStdString(st.stageType))
                .arg(100.0 * st.stageProgress, 0, 'f', 0);
  text += tr("  |  step %1  |  t = %2 s").arg(st.step).arg(st.time, 0, 'g', 4);
  if (st.cycle > 0) text += tr("  |  cycle %1").arg(st.cycle);
  text += tr("  |  %1 particle-steps/s").arg(st.particleStepsPerSecond, 0, 'g', 3);
  if (s.hasCurrent)
    text += tr("  |  p' = %1 kPa, q = %2 kPa, Z = %3").arg(s.current.p / 1e3, 0, 'f', 1).arg(s.current.q / 1e3, 0, 'f', 1)
                .arg(s.current.Z, 0, 'f', 2);
  if (!st.message.empty()) text += "  |  " + QString::fromStdString(st.message);
  m_status->setText(text);
}

QStringList MainWindow::saveScreenshots(const QString& dir) {
  QDir().mkpath(dir);
  QStringList written;
  auto save = [&](const QImage& image, const QString& name) {
    const QString path = QDir(dir).filePath(name);
    if (!image.isNull() && image.save(path)) written << path;
  };
  save(m_assembly->renderWidget()->grabImage(), "assembly.png");
  save(m_roses->renderWidget()->grabImage(), "roses.png");
  save(m_plots->stressPathView()->grab().toImage(), "stress_path.png");
  save(m_plots->loopView()->grab().toImage(), "tau_gamma.png");
  save(m_plots->cycleView()->grab().toImage(), "cycles.png");
  save(grab().toImage(), "window.png");
  return written;
}

}  // namespace fl::ui
