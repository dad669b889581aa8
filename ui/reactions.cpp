#include "ui/reactions.hpp"

#include <QFileDialog>
#include <QStatusBar>

#include "ui/main_window.hpp"
#include "ui/scene_panel.hpp"
#include "ui/sim_worker.hpp"

namespace fl::ui {

Reaction::Reaction(QAction* action, MainWindow* window) : QObject(action), m_window(window) {
  connect(action, &QAction::triggered, this, [this] { onTriggered(); });
}

void RunReaction::onTriggered() { window()->worker().run(); }
void PauseReaction::onTriggered() { window()->worker().pause(); }
void StepReaction::onTriggered() { window()->worker().step(stepSize()); }
void StopReaction::onTriggered() { window()->worker().stop(); }

void OpenSceneReaction::onTriggered() {
  const QString path = QFileDialog::getOpenFileName(window(), QObject::tr("Open scene"), QString(),
                                                    QObject::tr("Scene files (*.json)"));
  if (!path.isEmpty()) window()->openSceneFile(path);
}

void SaveSceneReaction::onTriggered() {
  const QString path = QFileDialog::getSaveFileName(window(), QObject::tr("Save scene"), QString(),
                                                    QObject::tr("Scene files (*.json)"));
  if (!path.isEmpty() && window()->scenePanel()->saveTo(path))
    window()->statusBar()->showMessage(QObject::tr("saved %1").arg(path), 5000);
}

void RestartFromCheckpointReaction::onTriggered() {
  const QString path = QFileDialog::getOpenFileName(window(), QObject::tr("Restart from checkpoint"), QString(),
                                                    QObject::tr("All files (*)"));
  if (!path.isEmpty()) window()->restartFromCheckpoint(path);
}

void ScreenshotReaction::onTriggered() {
  const QString dir = QFileDialog::getExistingDirectory(window(), QObject::tr("Save screenshots into"));
  if (dir.isEmpty()) return;
  const QStringList files = window()->saveScreenshots(dir);
  window()->statusBar()->showMessage(QObject::tr("%1 screenshots saved in %2").arg(files.size()).arg(dir), 5000);
}

}  // namespace fl::ui
