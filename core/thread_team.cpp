// A team of threads held for the step's loops (thread_team.hpp).
#include "thread_team.hpp"

#include "spin_wait.hpp"

namespace fl {

// The job is published on one line and the ends counted on another, so that a worker's spin and thread 0's
// wait each read one line the other side writes once per loop.
struct ThreadTeam::State {
  struct alignas(64) Posted {
    std::atomic<std::uint64_t> count{0};  // jobs posted; release: the job and its body are visible with it
    std::atomic<int> sleepers{0};         // threads asleep on count (after kSpins turns without a job)
    Job job = nullptr;                    // nullptr: leave the hold
    const void* body = nullptr;
    int threads = 0;
  };
  struct alignas(64) Ended {
    std::atomic<std::uint64_t> count{0};  // threads' ends of jobs, summed over the holds
  };
  Posted posted;
  Ended ended;
  int held = 0;              // thread 0's: the held team's size
  int cores = 0;             // thread 0's: omp_get_num_procs() when the hold began
  std::uint64_t endsSeen = 0;  // thread 0's: ended.count when the last job had ended
  int spins = kSpins;
};

ThreadTeam::ThreadTeam() : m_s(std::make_unique<State>()) {}
ThreadTeam::~ThreadTeam() = default;
ThreadTeam::ThreadTeam(ThreadTeam&&) noexcept = default;
ThreadTeam& ThreadTeam::operator=(ThreadTeam&&) noexcept = default;

// A job (or the end of the hold) for the held threads, and a wake-up for those asleep.
void ThreadTeam::post(State& s) {
  s.posted.count.fetch_add(1);  // sequentially consistent: ordered before the read of the sleepers
  if (s.posted.sleepers.load() > 0) s.posted.count.notify_all();
}

int ThreadTeam::held() const { return m_s->held; }
int ThreadTeam::cores() const { return m_s->held != 0 ? m_s->cores : omp_get_num_procs(); }

std::uint64_t ThreadTeam::begin() const { return m_s->posted.count.load(std::memory_order_relaxed); }

void ThreadTeam::enter(int threads) {
  m_s->held = threads;
  m_s->endsSeen = m_s->ended.count.load(std::memory_order_relaxed);
  m_s->cores = omp_get_num_procs();
  m_s->spins = spinsFor(threads, m_s->cores);
}

void ThreadTeam::dispatch(Job job, const void* body) {
  State& s = *m_s;
  s.posted.job = job;
  s.posted.body = body;
  s.posted.threads = s.held;
  post(s);
  job(body, 0, s.held);
  const std::uint64_t target = s.endsSeen + static_cast<std::uint64_t>(s.held - 1);
  for (int turn = 0; s.ended.count.load(std::memory_order_acquire) < target; ++turn) backOff(turn, s.spins);
  s.endsSeen = target;
}

void ThreadTeam::release() {
  State& s = *m_s;
  s.posted.job = nullptr;
  post(s);
  s.held = 0;
}

void ThreadTeam::serve(int t, std::uint64_t from) {
  State& s = *m_s;
  const int spins = spinsFor(omp_get_num_threads(), omp_get_num_procs());
  for (std::uint64_t seen = from;;) {
    std::uint64_t now;
    for (int turn = 0; (now = s.posted.count.load(std::memory_order_acquire)) == seen; ++turn) {
      if (turn < spins) {
        backOff(turn, spins);
        continue;
      }
      // a long serial stretch of thread 0 (or more threads than cores): sleep until the next post. The sleeper is
      // counted before count is read again, and post() reads the sleepers after it counts: one of the two sees
      // the other (both sequentially consistent), so a post is never missed.
      s.posted.sleepers.fetch_add(1);
      if (s.posted.count.load() == seen) s.posted.count.wait(seen);
      s.posted.sleepers.fetch_sub(1);
      turn = 0;
    }
    seen = now;
    const Job job = s.posted.job;
    if (job == nullptr) return;
    job(s.posted.body, t, s.posted.threads);
    s.ended.count.fetch_add(1, std::memory_order_release);
  }
}

}  // namespace fl
