/*
 * SimWorker: the one thread that owns the Runner (house-style §14, after Qt's Mandelbrot example).
 *  - Commands (load, run, pause, step, stop) go in as plain values through a mutex-protected queue and are
 *    applied between calls of runner.advance(k); k adapts so one call takes ~20 ms, so a pause or stop
 *    (also raised as std::atomic flags checked between calls) takes effect within a frame or two.
 *  - The worker publishes an immutable Snapshot (plain vectors) at most ~30 times a second by swapping a
 *    mutex-protected shared_ptr, then emits snapshotReady() (queued to the GUI thread). At most one
 *    notification is in flight, so a slow GUI just skips to the newest snapshot.
 *  - Exceptions never cross the thread boundary: they are caught here, the run is paused, the status
 *    carries the message and errorOccurred() is emitted (queued).
 * The Runner and Simulation are never touched by the GUI thread.
 */
#pragma once

#include <QObject>
#include <QString>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>

#include "core/scene.hpp"
#include "ui/snapshot.hpp"

namespace fl::ui {

// Throughput counters of the worker while it was running (for --measure and the status line).
struct WorkerStats {
  long steps = 0;              // steps advanced while running
  double particleSteps = 0;    // sum of N over those steps
  double runningSeconds = 0;   // wall time spent in the running state (advance + snapshots) [s]
  double advanceSeconds = 0;   // of which inside runner.advance() [s]
  long snapshots = 0;          // published
  double snapshotSeconds = 0;  // wall time building them [s]
};

class SimWorker : public QObject {
  Q_OBJECT

 public:
  explicit SimWorker(QObject* parent = nullptr);
  ~SimWorker() override;  // stops and joins the thread (safe during a run)

  // Commands: callable from any thread, applied by the worker between advance() calls.
  void loadScene(Scene scene);
  void loadCheckpoint(const std::string& path);
  void run();
  void pause();
  void step(long steps);
  void stop();  // ends the run; the next run() starts the scene again from the beginning

  // Newest published snapshot (nullptr before the first); cheap, thread-safe.
  std::shared_ptr<const Snapshot> latest() const;
  WorkerStats stats() const;
  void resetStats();
  // Upper bound on snapshots per second (default 30).
  void setMaxSnapshotRate(double perSecond) { m_minPublishInterval.store(1.0 / perSecond); }
  // Target wall time of one advance() call (default 0.02 s).
  void setChunkSeconds(double s) { m_chunkSeconds.store(s); }

 signals:
  void snapshotReady();
  void errorOccurred(const QString& message);

 private:
  struct LoadScene { Scene scene; };
  struct LoadCheckpoint { std::string path; };
  struct Run {};
  struct Step { long steps; };
  struct Pause {};
  struct Stop {};
  using Command = std::variant<LoadScene, LoadCheckpoint, Run, Step, Pause, Stop>;

  void post(Command c);
  void loop();
  void publish(bool force);
  void fail(const std::string& message);

  // shared with the GUI thread
  mutable std::mutex m_mutex;
  std::condition_variable m_wake;
  std::deque<Command> m_queue;
  bool m_quit = false;
  std::atomic<bool> m_pauseRequested{false};
  std::atomic<bool> m_stopRequested{false};
  mutable std::atomic<bool> m_notifyPending{false};  // cleared by latest() (const)
  std::atomic<double> m_minPublishInterval{1.0 / 30.0};
  std::atomic<double> m_chunkSeconds{0.02};
  mutable std::mutex m_snapshotMutex;
  std::shared_ptr<const Snapshot> m_latest;
  mutable std::mutex m_statsMutex;
  WorkerStats m_stats;

  // worker-thread only
  std::unique_ptr<Runner> m_runner;
  std::optional<Scene> m_scene;  // what run() after stop() restarts
  RunStatus m_status;
  bool m_running = false;
  bool m_stopped = false;
  long m_stepBudget = 0;
  long m_chunk = 10;
  double m_lastPublish = -1e9;
  double m_rateWindowStart = 0;
  double m_rateWindowParticleSteps = 0;

  std::thread m_thread;  // last: started after everything above is constructed
};

}  // namespace fl::ui
