/*
 * Reactions: each menu/toolbar action is a small object wired to the main window (after ParaView's
 * pqReaction), instead of one large slot file. A reaction owns nothing but its behaviour; it is parented to
 * its QAction and dies with it.
 */
#pragma once

#include <QAction>
#include <QObject>

namespace fl::ui {

class MainWindow;

class Reaction : public QObject {
  Q_OBJECT

 public:
  Reaction(QAction* action, MainWindow* window);

 protected:
  virtual void onTriggered() = 0;
  MainWindow* window() const { return m_window; }

 private:
  MainWindow* m_window;
};

class RunReaction final : public Reaction {
 public:
  using Reaction::Reaction;
 protected:
  void onTriggered() override;
};

class PauseReaction final : public Reaction {
 public:
  using Reaction::Reaction;
 protected:
  void onTriggered() override;
};

// One press advances a small fixed number of steps (stepSize()).
class StepReaction final : public Reaction {
 public:
  using Reaction::Reaction;
  static constexpr long stepSize() { return 100; }
 protected:
  void onTriggered() override;
};

class StopReaction final : public Reaction {
 public:
  using Reaction::Reaction;
 protected:
  void onTriggered() override;
};

class OpenSceneReaction final : public Reaction {
 public:
  using Reaction::Reaction;
 protected:
  void onTriggered() override;
};

class SaveSceneReaction final : public Reaction {
 public:
  using Reaction::Reaction;
 protected:
  void onTriggered() override;
};

class RestartFromCheckpointReaction final : public Reaction {
 public:
  using Reaction::Reaction;
 protected:
  void onTriggered() override;
};

class ScreenshotReaction final : public Reaction {
 public:
  using Reaction::Reaction;
 protected:
  void onTriggered() override;
};

}  // namespace fl::ui
