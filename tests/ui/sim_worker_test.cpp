// The GUI's worker/controller protocol without a window (house-style §14): commands posted from the GUI
// thread (and from a second thread) are applied between advance() chunks, snapshots are immutable and
// their serials only grow, pause/step/stop act exactly, errors never cross the thread boundary, and the
// destructor joins a running worker. Needs only QtCore, so scripts/ci-gui-tsan.sh builds it with
// ThreadSanitizer (clang) to check the worker's synchronisation.
#include <gtest/gtest.h>

#include <QCoreApplication>
#include <QElapsedTimer>

#include <array>
#include <atomic>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/scene.hpp"
#include "ui/sim_worker.hpp"
#include "ui_test_support.hpp"

using namespace fl;
using namespace fl::ui;
using fl::ui::test::waitUntil;

namespace {

class CoreEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { m_app = std::make_unique<QCoreApplication>(m_argc, m_argv.data()); }
  void TearDown() override { m_app.reset(); }

 private:
  int m_argc = 1;
  char m_arg0[32] = "sim_worker_test";
  std::array<char*, 2> m_argv{m_arg0, nullptr};
  std::unique_ptr<QCoreApplication> m_app;
};
[[maybe_unused]] auto* const g_env = ::testing::AddGlobalTestEnvironment(new CoreEnvironment);

Scene tinyScene(bool withCycles = false, int count = 120) {
  return parseScene(nlohmann::json::parse(test::tinySceneJson(withCycles, count)), "tiny.json");
}
RunState stateOf(const SimWorker& w) {
  auto s = w.latest();
  return s ? s->status.state : RunState::Empty;
}
long stepOf(const SimWorker& w) {
  auto s = w.latest();
  return s ? s->status.step : -1;
}

// Counts notifications and checks, on the GUI thread, that every snapshot it is handed is newer.
struct Listener {
  explicit Listener(SimWorker& w) : worker(w) {
    // queued to this (GUI) thread, as MainWindow connects them; a context-free lambda would run on the worker
    QObject::connect(&w, &SimWorker::snapshotReady, &w, [this] {
      ++notifications;
      auto s = worker.latest();
      if (s && s->serial < lastSerial) serialWentBack = true;
      if (s) lastSerial = s->serial;
    }, Qt::QueuedConnection);
    QObject::connect(&w, &SimWorker::errorOccurred, &w, [this](const QString& m) {
      ++errors;
      lastError = m.toStdString();
    }, Qt::QueuedConnection);
  }
  SimWorker& worker;
  int notifications = 0, errors = 0;
  long lastSerial = 0;
  bool serialWentBack = false;
  std::string lastError;
};

}  // namespace

TEST(UiSimWorker, RunsToTheEndPublishingNewerSnapshots) {
  SimWorker w;
  Listener l(w);
  w.setMaxSnapshotRate(200);  // many snapshots: more hand-overs between the threads
  w.loadScene(tinyScene(true));
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Ready; }));
  w.run();
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Finished; }, 120000));
  auto s = w.latest();
  EXPECT_GT(s->status.step, 0);
  EXPECT_EQ(s->status.stageIndex, s->status.stageCount);
  EXPECT_FALSE(s->positions.empty());
  EXPECT_GT(l.notifications, 2);
  EXPECT_FALSE(l.serialWentBack);
  EXPECT_EQ(l.errors, 0);
  // the stats of the last chunk are booked right after its snapshot is published
  EXPECT_TRUE(waitUntil([&] { return w.stats().steps == s->status.step; }, 3000))
      << w.stats().steps << " vs " << s->status.step;
  EXPECT_GE(w.stats().snapshots, l.notifications);
}

TEST(UiSimWorker, StepIsExactPauseHoldsStopRestarts) {
  SimWorker w;
  w.loadScene(tinyScene());
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Ready; }));
  w.step(137);
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Paused; }));
  EXPECT_EQ(stepOf(w), 137);
  w.run();
  ASSERT_TRUE(waitUntil([&] { return stepOf(w) > 400; }));
  w.pause();
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Paused; }, 3000));
  const long paused = stepOf(w);
  waitUntil([] { return false; }, 200);
  EXPECT_EQ(stepOf(w), paused) << "stepping while paused";
  w.stop();
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Ready; }, 3000));
  w.step(10);  // after a stop the scene starts again from step 0
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Paused; }));
  EXPECT_EQ(stepOf(w), 10);
}

TEST(UiSimWorker, ErrorsAreReportedNotThrownAcrossThreads) {
  SimWorker w;
  Listener l(w);
  w.loadCheckpoint("/nonexistent/fabriclab-worker-test.ckpt");
  ASSERT_TRUE(waitUntil([&] { return l.errors == 1; }));
  EXPECT_EQ(stateOf(w), RunState::Error);
  EXPECT_NE(l.lastError.find("fabriclab-worker-test.ckpt"), std::string::npos) << l.lastError;
  // the worker is still alive and takes the next scene
  w.loadScene(tinyScene());
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Ready; }));
}

TEST(UiSimWorker, CommandsFromTwoThreadsWhileRunning) {
  SimWorker w;
  Listener l(w);
  w.setMaxSnapshotRate(500);
  w.setChunkSeconds(0.002);  // short chunks: commands land between many advance() calls
  w.loadScene(tinyScene());
  ASSERT_TRUE(waitUntil([&] { return stateOf(w) == RunState::Ready; }));
  w.run();
  std::atomic<bool> done{false};
  std::atomic<long> reads{0};
  std::thread other([&] {
    for (int k = 0; k < 200 && !done; ++k) {
      if (k % 3 == 0) w.pause();
      else if (k % 3 == 1) w.step(5);
      else w.run();
      if (auto s = w.latest()) reads += s->status.step >= 0;
      (void)w.stats();
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    w.pause();
    done = true;
  });
  waitUntil([&] { return done.load(); }, 60000);
  other.join();
  // A Paused snapshot may come from an earlier pause while the last few commands (a step(5), the final
  // pause) are still queued: wait until the worker is paused and has stopped moving, then check it stays so.
  long paused = -1;
  ASSERT_TRUE(waitUntil([&] {
    if (stateOf(w) != RunState::Paused) return false;
    const long s = stepOf(w);
    waitUntil([] { return false; }, 200);
    if (stepOf(w) != s || stateOf(w) != RunState::Paused) return false;
    paused = s;
    return true;
  }, 10000));
  waitUntil([] { return false; }, 300);
  EXPECT_EQ(stepOf(w), paused) << "stepping after the final pause";
  EXPECT_EQ(stateOf(w), RunState::Paused);
  EXPECT_GT(reads.load(), 0);
  EXPECT_FALSE(l.serialWentBack);
  EXPECT_EQ(l.errors, 0);
}

TEST(UiSimWorker, DestructorJoinsARunningWorker) {
  QElapsedTimer t;
  {
    auto w = std::make_unique<SimWorker>();
    w->loadScene(tinyScene(false, 400));
    ASSERT_TRUE(waitUntil([&] { return stateOf(*w) == RunState::Ready; }));
    w->run();
    ASSERT_TRUE(waitUntil([&] { return stepOf(*w) > 50; }));
    t.start();
  }
  EXPECT_LT(t.elapsed(), 3000);
}
