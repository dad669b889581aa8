// Crash safety of `fabriclab-run` (issue 8): a run killed at any moment loses nothing already written.
//  - KillAnywhere: SIGKILLs a run of a small scene at pseudo-random moments (fixed seed), tens of times; the
//    run is continued each time from its newest checkpoint (`--restart`) in the same results folder, as a
//    user would. After every kill: every line of timeseries.csv / cycles.csv is complete (header's column
//    count, numeric fields) and what was there before is still there (the old contents are a prefix);
//    stages.json and scene.json parse; every checkpoints/*.ckpt loads with Runner::fromCheckpoint. At the
//    end the newest checkpoint is loaded and advanced in-process.
//  - SIGINT/SIGTERM: exit code 130, checkpoints/interrupted.ckpt loads, restarts and runs on.
//  - Output safety: a non-empty results folder (no --overwrite), a file in place of the folder and an
//    uncreatable folder are refused before the run starts, with a message naming the folder.
// Timing only decides where the kills land; every check holds at any moment, so the outcome does not
// depend on the machine's load. FL_CRASH_KILLS and FL_CRASH_SECONDS (env) change the kill count and the
// time budget of KillAnywhere (defaults 30 kills, 60 s; the loop stops early when the budget is spent,
// but only after at least 10 kills).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/runner.hpp"

extern char** environ;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

std::string runExe() {
  if (const char* e = std::getenv("FABRICLAB_RUN")) return e;
  return FL_RUN_EXE;
}

long envLong(const char* name, long def) {
  const char* v = std::getenv(name);
  return v && *v ? std::atol(v) : def;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// ~300 spheres, mass scaling 100, one thread; checkpoints every 400 steps, samples every 100 steps, and a
// short cyclic stage so cycles.csv and the cyclic state appear in checkpoints.
std::string sceneJson(const fs::path& out) {
  nlohmann::json j = nlohmann::json::parse(R"({
    "name": "crash safety",
    "specimen": {"count": 300, "solid_fraction": 0.3, "seed": 5},
    "numerics": {"time_step_factor": 0.3, "local_damping": 0.1, "density_scale": 100, "threads": 1},
    "servo": {"max_strain_rate": 20, "max_inertial_number": 0.02, "unbalanced_tolerance": 0.02},
    "output": {"sample_interval": 100, "checkpoint_interval": 400, "check_interval": 50},
    "stages": [
      {"type": "isotropic_compression", "name": "compress", "pressure": 50000, "friction": 0.1,
       "friction_after": 0.235},
      {"type": "hold", "name": "hold", "steps": 600},
      {"type": "cyclic", "name": "cycles", "drainage": "undrained", "amplitude": 2e-4, "cycles": 50,
       "samples_per_cycle": 8, "strain_rate": 0.5}
    ]
  })");
  j["output"]["directory"] = out.string();
  return j.dump(2);
}

struct Child {
  pid_t pid = -1;
};

// Starts fabriclab-run with <args>; stdout and stderr go to <log>.out / <log>.err.
Child spawnRun(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> all{runExe()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  const std::string out = log.string() + ".out", err = log.string() + ".err";
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  Child c;
  const int rc = posix_spawn(&c.pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("cannot start " + all[0] + ": " + std::strerror(rc));
  return c;
}

// Waits for the child; returns the exit code, or 128 + signal. Kills it after <timeout>.
int waitChild(Child c, std::chrono::seconds timeout = std::chrono::seconds(120)) {
  const auto end = Clock::now() + timeout;
  for (;;) {
    int st = 0;
    const pid_t r = waitpid(c.pid, &st, WNOHANG);
    if (r == c.pid) return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    if (Clock::now() > end) {
      kill(c.pid, SIGKILL);
      waitpid(c.pid, &st, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// Returns true if the child has already exited (its status in <code>).
bool exited(const Child& c, int& code) {
  int st = 0;
  if (waitpid(c.pid, &st, WNOHANG) != c.pid) return false;
  code = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return true;
}

// The file's complete lines: a kill inside a record's write(2) may leave its head as an unfinished last line
// (the kernel copies page by page and stops at a page boundary for a fatal signal), which readers ignore
// (app/report_csv.hpp) and a restart drops (AppendLog).
std::string completeLines(const std::string& text) { return text.substr(0, text.find_last_of('\n') + 1); }

// Every complete line: the header's column count, each field a number.
void checkCsv(const fs::path& p, const std::string& text) {
  SCOPED_TRACE(p.string());
  if (text.empty()) return;  // created, header not yet written
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  const auto cols = std::count(line.begin(), line.end(), ',') + 1;
  ASSERT_GT(cols, 1) << "bad header: " << line;
  long n = 1;
  while (std::getline(in, line)) {
    ++n;
    ASSERT_EQ(std::count(line.begin(), line.end(), ',') + 1, cols) << "line " << n << ": " << line;
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) {
      char* end = nullptr;
      std::strtod(f.c_str(), &end);
      ASSERT_TRUE(!f.empty() && end == f.c_str() + f.size()) << "line " << n << " field '" << f << "'";
    }
  }
}

// Files in <dir>: what every reader must find after a kill. <before> holds the logs as they were at the
// previous check; they must still start with that text (nothing written is ever lost).
int checkResults(const fs::path& dir, std::map<std::string, std::string>& before) {
  int checkpoints = 0;
  for (const char* log : {"timeseries.csv", "cycles.csv"}) {
    const fs::path p = dir / log;
    if (!fs::exists(p)) continue;
    // a restart drops an unfinished last line: every row of a check holds a whole record, and a row cut short
    // that a restart kept would be a malformed row (or a wrong number) at the next check
    const std::string text = completeLines(slurp(p));
    checkCsv(p, text);
    const std::string& old = before[log];
    EXPECT_EQ(text.compare(0, old.size(), old), 0) << p << ": earlier records were lost or changed";
    before[log] = text;
  }
  for (const char* js : {"stages.json", "scene.json"}) {
    const fs::path p = dir / js;
    if (!fs::exists(p)) continue;
    nlohmann::json j;
    EXPECT_NO_THROW(j = nlohmann::json::parse(slurp(p))) << p;
    if (std::string(js) == "stages.json") {
      EXPECT_TRUE(j.contains("stages") && j["stages"].is_array()) << p;
    }
  }
  if (fs::exists(dir / "checkpoints"))
    for (const auto& e : fs::directory_iterator(dir / "checkpoints")) {
      const std::string name = e.path().filename().string();
      if (e.path().extension() != ".ckpt") continue;  // "<name>.ckpt.tmp.<pid>": a killed atomic write
      EXPECT_NO_THROW(fl::Runner::fromCheckpoint(e.path().string())) << e.path();
      ++checkpoints;
    }
  return checkpoints;
}

// The checkpoint of dir with the most steps; unfinishedOnly: of those with stages left to run (a run killed
// after its last stage's checkpoint, or one that finished, holds a checkpoint with nothing left).
fs::path newestCheckpoint(const fs::path& dir, bool unfinishedOnly = false) {
  fs::path best;
  long bestStep = -1;
  if (!fs::exists(dir / "checkpoints")) return best;
  for (const auto& e : fs::directory_iterator(dir / "checkpoints")) {
    if (e.path().extension() != ".ckpt") continue;
    const fl::Runner r = fl::Runner::fromCheckpoint(e.path().string());
    if (unfinishedOnly && r.finished()) continue;
    const long step = r.simulation().stepCount();
    if (step > bestStep) bestStep = step, best = e.path();
  }
  return best;
}

class CrashSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    m_root = fs::temp_directory_path() /
             ("fl-crash-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(m_root);
    fs::create_directories(m_root);
    m_scene = m_root / "scene.json";
    std::ofstream(m_scene) << sceneJson(m_root / "results");
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(m_root);
    else std::fprintf(stderr, "kept %s for inspection\n", m_root.c_str());
  }
  std::string errText(const std::string& log) { return slurp(m_root / (log + ".err")); }

  fs::path m_root, m_scene;
};

}  // namespace

TEST_F(CrashSafety, KillAnywhereLosesNothingAndRestarts) {
  const long kills = envLong("FL_CRASH_KILLS", 30);
  const double budget = static_cast<double>(envLong("FL_CRASH_SECONDS", 60));
  std::mt19937 rng(20240808);  // fixed: the same kill schedule on every run (the landing spots vary with load)
  std::uniform_int_distribution<int> delayMs(150, 2500);
  const fs::path results = m_root / "results";
  const fs::path lastFinished = m_root / "results-finished";
  std::map<std::string, std::string> before;
  const auto t0 = Clock::now();
  int survived = 0, restarts = 0, fresh = 0, finished = 0, maxCheckpoints = 0;
  for (long k = 0; k < kills; ++k) {
    if (k >= 10 && std::chrono::duration<double>(Clock::now() - t0).count() > budget) break;
    // Continue from the newest checkpoint if there is one, else start (again) from the scene.
    const fs::path ck = newestCheckpoint(results);
    Child c;
    if (ck.empty()) {
      c = spawnRun({m_scene.string(), "--overwrite", "--quiet"}, m_root / "run");
      before.clear();  // a fresh run with --overwrite replaces the previous results
      ++fresh;
    } else {
      c = spawnRun({"--restart", ck.string(), "--quiet"}, m_root / "run");
      ++restarts;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(delayMs(rng)));
    int code = 0;
    if (exited(c, code)) {
      // Finished before the kill: fine, but only with success; start a fresh run next time.
      ASSERT_EQ(code, 0) << "run exited early with " << code << ": " << errText("run");
      ++finished;
      checkResults(results, before);
      fs::remove_all(lastFinished);  // keep the last finished run aside: its checkpoints restart too
      fs::rename(results, lastFinished);
      before.clear();
      continue;
    }
    ASSERT_EQ(kill(c.pid, SIGKILL), 0);
    const int st = waitChild(c);
    ASSERT_EQ(st, 128 + SIGKILL) << "run ended with " << st << " instead of being killed: " << errText("run");
    const int n = checkResults(results, before);
    if (HasFailure()) {
      ADD_FAILURE() << "after kill " << k + 1;
      return;
    }
    maxCheckpoints = std::max(maxCheckpoints, n);
    ++survived;
  }
  // The newest checkpoint with stages left restarts and runs on in-process.
  fs::path ck = newestCheckpoint(results, true);
  if (ck.empty()) ck = newestCheckpoint(lastFinished, true);  // the last run finished before its kill
  ASSERT_FALSE(ck.empty()) << "no checkpoint with stages left was ever written";
  fl::Runner r = fl::Runner::fromCheckpoint(ck.string());
  const long step0 = r.simulation().stepCount();
  EXPECT_NO_THROW(r.advance(200));
  EXPECT_GT(r.simulation().stepCount(), step0);
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("[crash-safety] kills survived: %d (restarts from a checkpoint %d, fresh starts %d, runs finished "
              "before the kill %d), up to %d checkpoints per check, %.1f s\n",
              survived, restarts, fresh, finished, maxCheckpoints, secs);
  EXPECT_GE(survived, 10);
}

TEST_F(CrashSafety, SigtermAndSigintWriteInterruptedCheckpointAndExit130) {
  const fs::path results = m_root / "results";
  for (int sig : {SIGTERM, SIGINT}) {
    SCOPED_TRACE(sig == SIGTERM ? "SIGTERM" : "SIGINT");
    fs::remove_all(results);
    Child c = spawnRun({m_scene.string(), "--quiet"}, m_root / "run");
    // Wait until the run is stepping (its first samples are on disk), then interrupt it.
    const auto end = Clock::now() + std::chrono::seconds(60);
    int early = 0;
    while (Clock::now() < end && !(fs::exists(results / "timeseries.csv") && fs::file_size(results / "timeseries.csv") > 2000))
      if (exited(c, early)) FAIL() << "run exited with " << early << ": " << errText("run");
      else std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_EQ(kill(c.pid, sig), 0);
    ASSERT_EQ(waitChild(c), 130) << errText("run");
    const fs::path ck = results / "checkpoints" / "interrupted.ckpt";
    ASSERT_TRUE(fs::exists(ck)) << errText("run");
    EXPECT_NE(errText("run").find("interrupted.ckpt"), std::string::npos) << "the message should name the checkpoint";
    std::map<std::string, std::string> before;
    checkResults(results, before);
    fl::Runner r = fl::Runner::fromCheckpoint(ck.string());
    const long step0 = r.simulation().stepCount();
    EXPECT_GT(step0, 0);
    EXPECT_NO_THROW(r.advance(100));
    // ... and the command itself continues from it (interrupted again once it is running).
    Child again = spawnRun({"--restart", ck.string(), "--quiet"}, m_root / "restart");
    const std::size_t size0 = fs::file_size(results / "timeseries.csv");
    const auto end2 = Clock::now() + std::chrono::seconds(60);
    early = 0;
    while (Clock::now() < end2 && fs::file_size(results / "timeseries.csv") < size0 + 1000)
      if (exited(again, early)) FAIL() << "restart exited with " << early << ": " << errText("restart");
      else std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_EQ(kill(again.pid, sig), 0);
    ASSERT_EQ(waitChild(again), 130) << errText("restart");
    EXPECT_GT(fl::Runner::fromCheckpoint(ck.string()).simulation().stepCount(), step0);
    checkResults(results, before);
  }
}

TEST_F(CrashSafety, NonEmptyResultsFolderIsRefusedWithoutOverwrite) {
  const fs::path results = m_root / "results";
  fs::create_directories(results);
  std::ofstream(results / "old-result.txt") << "precious\n";
  Child c = spawnRun({m_scene.string(), "--out", results.string(), "--quiet"}, m_root / "run");
  const int code = waitChild(c, std::chrono::seconds(30));
  EXPECT_TRUE(code == 1 || code == 2) << code;
  const std::string err = errText("run");
  EXPECT_NE(err.find(results.string()), std::string::npos) << err;
  EXPECT_NE(err.find("not empty"), std::string::npos) << err;
  EXPECT_EQ(slurp(m_root / "run.out").find("FabricLab:"), std::string::npos) << "the run started";
  EXPECT_EQ(slurp(results / "old-result.txt"), "precious\n");
  EXPECT_FALSE(fs::exists(results / "timeseries.csv"));
}

TEST_F(CrashSafety, OverwriteReplacesThePreviousResultsAndKeepsOtherFiles) {
  // A short scene (two 300-step holds of the gas; the compression would take 75 s per run under ASan): run
  // it, then again with --overwrite into the same folder.
  nlohmann::json j = nlohmann::json::parse(sceneJson(m_root / "results"));
  j["stages"] = nlohmann::json::array({j["stages"][1], j["stages"][1]});
  j["stages"][0]["name"] = "settle";
  j["stages"][0]["steps"] = 300;
  j["stages"][1]["steps"] = 300;
  const fs::path scene = m_root / "short.json", results = m_root / "results";
  std::ofstream(scene) << j.dump(2);
  ASSERT_EQ(waitChild(spawnRun({scene.string(), "--quiet"}, m_root / "run")), 0) << errText("run");
  const std::string first = slurp(results / "timeseries.csv"), stages = slurp(results / "stages.json");
  ASSERT_GT(first.size(), 200u);
  std::ofstream(results / "my-notes.txt") << "keep me\n";
  fs::create_directories(results / "checkpoints");
  std::ofstream(results / "checkpoints" / "stale.ckpt") << "old";
  ASSERT_EQ(waitChild(spawnRun({scene.string(), "--overwrite", "--quiet"}, m_root / "run")), 0) << errText("run");
  // the same deterministic run: identical files, not the old rows followed by the new ones
  EXPECT_EQ(slurp(results / "timeseries.csv"), first);
  // (stages.json holds wall times: compare what it lists)
  const auto countStages = [](const std::string& text) {
    const auto v = nlohmann::json::parse(text);
    return v.is_array() ? v.size() : v.value("stages", nlohmann::json::array()).size();
  };
  EXPECT_EQ(countStages(slurp(results / "stages.json")), countStages(stages));
  EXPECT_GE(countStages(stages), 2u);
  EXPECT_FALSE(fs::exists(results / "checkpoints" / "stale.ckpt"));
  EXPECT_EQ(slurp(results / "my-notes.txt"), "keep me\n");
}

TEST_F(CrashSafety, UnwritableResultsFolderIsRefusedBeforeTheRun) {
  const fs::path file = m_root / "a-file";
  std::ofstream(file) << "not a folder\n";
  struct Case {
    std::string out, expect;
  };
  std::vector<Case> cases{{file.string(), "not a folder"},
                          {(file / "sub").string(), "cannot create"},
                          {"/proc/fabriclab-results", "cannot create"}};
  if (::geteuid() != 0) {  // root writes anywhere: a read-only folder only stops other users
    const fs::path ro = m_root / "read-only";
    fs::create_directories(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    cases.push_back({(ro / "results").string(), "cannot create"});
  }
  for (const Case& k : cases) {
    SCOPED_TRACE(k.out);
    const auto t0 = Clock::now();
    Child c = spawnRun({m_scene.string(), "--out", k.out, "--quiet"}, m_root / "run");
    const int code = waitChild(c, std::chrono::seconds(30));
    EXPECT_TRUE(code == 1 || code == 2) << code;
    const std::string err = errText("run");
    EXPECT_NE(err.find(k.out), std::string::npos) << err;
    EXPECT_NE(err.find(k.expect), std::string::npos) << err;
    EXPECT_EQ(slurp(m_root / "run.out").find("FabricLab:"), std::string::npos) << "the run started";
    EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 20.0);
  }
}
