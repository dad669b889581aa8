/*
 * MainWindow: the FabricLab desktop lab. Central 3D view of the assembly; docks for the scene/protocol
 * panel, the rose diagrams, the live plots and the "what you are seeing" notes; run controls in a toolbar
 * (each action a small reaction object, reactions.hpp); a status line with stage, step, simulated time,
 * cycle and particle-steps per second.
 * Threading: the SimWorker owns the Runner; this window only receives snapshots (queued signal), draws the
 * newest one, and shows worker errors as a (non-blocking) message box plus a status message.
 */
#pragma once

#include <QMainWindow>
#include <QString>
#include <QStringList>

#include <memory>

#include "core/scene.hpp"
#include "ui/snapshot.hpp"

class QLabel;
class QToolBar;

namespace fl::ui {

class AssemblyView;
class PlotsView;
class RoseView;
class ScenePanel;
class SimWorker;
class TeachingPanel;

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  // Loads a scene file (validated); on error shows the message (naming file and field), returns false.
  bool openSceneFile(const QString& path);
  void openScene(const Scene& scene);
  void restartFromCheckpoint(const QString& path);
  void setPresetDirectory(const QString& dir);

  SimWorker& worker() const { return *m_worker; }
  AssemblyView* assemblyView() const { return m_assembly; }
  RoseView* roseView() const { return m_roses; }
  PlotsView* plotsView() const { return m_plots; }
  ScenePanel* scenePanel() const { return m_scenePanel; }
  TeachingPanel* teachingPanel() const { return m_teaching; }
  std::shared_ptr<const Snapshot> shownSnapshot() const { return m_shown; }
  QString statusText() const;
  QString lastError() const { return m_lastError; }
  int errorCount() const { return m_errorCount; }
  long snapshotsShown() const { return m_snapshotsShown; }

  // Saves assembly.png (3D view with force chains), roses.png, stress_path.png, tau_gamma.png,
  // cycles.png and window.png into dir; returns the files written.
  QStringList saveScreenshots(const QString& dir);
  void showError(const QString& message);

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  void onSnapshotReady();
  void updateStatus(const Snapshot& s);

  std::unique_ptr<SimWorker> m_worker;
  AssemblyView* m_assembly = nullptr;
  RoseView* m_roses = nullptr;
  PlotsView* m_plots = nullptr;
  ScenePanel* m_scenePanel = nullptr;
  TeachingPanel* m_teaching = nullptr;
  QLabel* m_status = nullptr;
  std::shared_ptr<const Snapshot> m_shown;
  QString m_lastError;
  int m_errorCount = 0;
  long m_snapshotsShown = 0;
  QString m_lastStateError;
};

}  // namespace fl::ui
