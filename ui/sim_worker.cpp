#include "ui/sim_worker.hpp"

#include <algorithm>
#include <chrono>
#include <exception>

namespace fl::ui {

namespace {
double now() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}
}  // namespace

SimWorker::SimWorker(QObject* parent) : QObject(parent) {
  m_thread = std::thread([this] { loop(); });
}

SimWorker::~SimWorker() {
  {
    std::lock_guard lk(m_mutex);
    m_quit = true;
  }
  m_pauseRequested = true;  // the current advance() chunk is short; the loop sees m_quit right after it
  m_wake.notify_all();
  if (m_thread.joinable()) m_thread.join();
}

void SimWorker::post(Command c) {
  {
    std::lock_guard lk(m_mutex);
    m_queue.push_back(std::move(c));
  }
  m_wake.notify_all();
}

void SimWorker::loadScene(Scene scene) {
  m_pauseRequested = true;  // stop the current run at once; the load then replaces it
  post(LoadScene{std::move(scene)});
}
void SimWorker::loadCheckpoint(const std::string& path) {
  m_pauseRequested = true;
  post(LoadCheckpoint{path});
}
void SimWorker::run() {
  m_pauseRequested = false;
  post(Run{});
}
void SimWorker::pause() {
  m_pauseRequested = true;  // interrupts the run before the queue is read
  post(Pause{});            // and keeps its place in the order of commands (run, pause -> paused)
}
void SimWorker::step(long steps) { post(Step{steps}); }
void SimWorker::stop() {
  m_stopRequested = true;
  post(Stop{});
}

std::shared_ptr<const Snapshot> SimWorker::latest() const {
  std::lock_guard lk(m_snapshotMutex);
  m_notifyPending = false;  // the GUI has caught up: the next publish may notify again
  return m_latest;
}

WorkerStats SimWorker::stats() const {
  std::lock_guard lk(m_statsMutex);
  return m_stats;
}
void SimWorker::resetStats() {
  std::lock_guard lk(m_statsMutex);
  m_stats = {};
}

void SimWorker::fail(const std::string& message) {
  m_running = false;
  m_stepBudget = 0;
  m_status.state = RunState::Error;
  m_status.message = message;
  publish(true);
  emit errorOccurred(QString::fromStdString(message));
}

void SimWorker::publish(bool force) {
  const double t = now();
  if (!force && t - m_lastPublish < m_minPublishInterval.load()) return;
  m_lastPublish = t;
  if (m_runner) {
    const Runner& r = *m_runner;
    m_status.stageIndex = r.stageIndex();
    m_status.stageCount = r.stageCount();
    const StageSpec* st = r.currentStage();
    m_status.stageName = st ? st->name : "";
    m_status.stageType = st ? stageTypeName(st->type) : "";
    m_status.step = r.simulation().stepCount();
    m_status.time = r.simulation().time();
    m_status.cycle = r.currentCycle();
    m_status.stageProgress = st ? r.stageProgress() : 1.0;
  }
  std::shared_ptr<const Snapshot> previous;
  {
    std::lock_guard lk(m_snapshotMutex);
    previous = m_latest;
  }
  std::shared_ptr<Snapshot> snap;
  try {
    if (m_runner) {
      snap = std::make_shared<Snapshot>(makeSnapshot(*m_runner, m_status, previous.get()));
    } else {
      snap = std::make_shared<Snapshot>();
      snap->status = m_status;
      snap->serial = previous ? previous->serial + 1 : 1;
    }
  } catch (const std::exception& e) {
    // measuring a broken state can throw too; publish the status alone
    snap = std::make_shared<Snapshot>();
    snap->status = m_status;
    snap->status.message = e.what();
    snap->serial = previous ? previous->serial + 1 : 1;
  }
  {
    std::lock_guard lk(m_statsMutex);
    ++m_stats.snapshots;
    m_stats.snapshotSeconds += now() - t;
  }
  {
    std::lock_guard lk(m_snapshotMutex);
    m_latest = std::move(snap);
  }
  if (!m_notifyPending.exchange(true)) emit snapshotReady();
}

void SimWorker::loop() {
  std::deque<Command> commands;
  for (;;) {
    {
      std::unique_lock lk(m_mutex);
      const bool busy = m_runner && (m_running || m_stepBudget > 0);
      if (!busy)
        m_wake.wait(lk, [&] { return m_quit || !m_queue.empty() || m_stopRequested || m_pauseRequested; });
      if (m_quit) break;
      commands.swap(m_queue);
    }
    // Pause and stop come first: a pause posted after a run must win, and it must act between chunks.
    if (m_pauseRequested.exchange(false) && (m_running || m_stepBudget > 0)) {
      m_running = false;
      m_stepBudget = 0;
      if (m_status.state == RunState::Running) m_status.state = RunState::Paused;
      publish(true);
    }
    if (m_stopRequested.exchange(false)) {
      m_running = false;
      m_stepBudget = 0;
    }
    for (Command& c : commands) {
      try {
        if (auto* load = std::get_if<LoadScene>(&c)) {
          m_running = false;
          m_stepBudget = 0;
          m_runner.reset();
          m_scene = load->scene;
          m_status = {};
          m_status.sceneName = m_scene->name;
          m_status.message = "building the specimen...";
          m_status.state = RunState::Empty;
          publish(true);
          m_runner = std::make_unique<Runner>(*m_scene);
          m_stopped = false;
          m_status.state = RunState::Ready;
          m_status.message.clear();
          publish(true);
        } else if (auto* ck = std::get_if<LoadCheckpoint>(&c)) {
          m_running = false;
          m_stepBudget = 0;
          m_runner.reset();
          m_status = {};
          m_runner = std::make_unique<Runner>(Runner::fromCheckpoint(ck->path));
          m_scene = m_runner->scene();
          m_status.sceneName = m_scene->name;
          m_status.state = RunState::Ready;
          m_status.message = "restarted from " + ck->path;
          m_stopped = false;
          publish(true);
        } else if (std::holds_alternative<Pause>(c)) {
          m_running = false;
          m_stepBudget = 0;
          if (m_status.state == RunState::Running) m_status.state = RunState::Paused;
          publish(true);
        } else if (std::holds_alternative<Stop>(c)) {
          m_running = false;
          m_stepBudget = 0;
          if (m_runner) {
            m_stopped = true;
            m_status.state = RunState::Ready;
            m_status.message = "stopped; Run starts the scene again";
          }
          publish(true);
        } else if (std::holds_alternative<Run>(c) || std::holds_alternative<Step>(c)) {
          if (m_stopped && m_scene) {  // a stopped run starts again from the scene
            m_runner.reset();
            m_runner = std::make_unique<Runner>(*m_scene);
            m_stopped = false;
            m_status.message.clear();
          }
          if (!m_runner || m_runner->finished()) continue;
          if (auto* s = std::get_if<Step>(&c)) {
            m_stepBudget += s->steps;
            m_running = false;
          } else {
            m_running = true;
          }
          m_status.state = RunState::Running;
          m_status.message.clear();
          m_rateWindowStart = now();
          m_rateWindowParticleSteps = 0;
        }
      } catch (const std::exception& e) {
        fail(e.what());
      }
    }
    commands.clear();

    if (!m_runner || !(m_running || m_stepBudget > 0)) continue;
    const long k = m_running ? m_chunk : std::min(m_chunk, m_stepBudget);
    const double n = static_cast<double>(m_runner->simulation().particles().size());
    const double t0 = now();
    bool more = true;
    long done = 0;
    try {
      const long before = m_runner->simulation().stepCount();
      more = m_runner->advance(k);
      done = m_runner->simulation().stepCount() - before;
    } catch (const std::exception& e) {
      fail(e.what());
      continue;
    }
    const double t1 = now();
    // Aim each advance() at ~20 ms: short enough for pause/stop to feel immediate, long enough that the
    // loop's overhead is negligible.
    const double dt = std::max(t1 - t0, 1e-6);
    const double target = m_chunkSeconds.load();
    const double scale = std::clamp(target / dt, 0.5, 2.0);
    m_chunk = std::clamp(static_cast<long>(static_cast<double>(std::max(k, 1L)) * scale), 1L, 1000000L);
    if (!m_running) m_stepBudget = std::max(0L, m_stepBudget - std::max(done, k));
    m_rateWindowParticleSteps += n * static_cast<double>(done);
    if (t1 - m_rateWindowStart > 1.0) {
      m_status.particleStepsPerSecond = m_rateWindowParticleSteps / (t1 - m_rateWindowStart);
      m_rateWindowStart = t1;
      m_rateWindowParticleSteps = 0;
    }
    if (!more || m_runner->finished()) {
      m_running = false;
      m_stepBudget = 0;
      m_status.state = RunState::Finished;
      publish(true);
    } else if (!m_running && m_stepBudget == 0) {
      m_status.state = RunState::Paused;
      publish(true);
    } else {
      publish(false);
    }
    std::lock_guard lk(m_statsMutex);
    m_stats.steps += done;
    m_stats.particleSteps += n * static_cast<double>(done);
    m_stats.advanceSeconds += t1 - t0;
    m_stats.runningSeconds += now() - t0;
  }
}

}  // namespace fl::ui
