// Dynamic balance of the step's parallel loops (issue 6: the 2-thread speed-up on shared hosts).
//
// Each thread owns a contiguous share of the items of one loop (particles, or chunks of pairs) and claims it
// run by run from its front; once its own share is empty it takes runs from the back of the share before its
// own (thread t - 1, thread 0 from the last one), whose back borders its own front. So a thread the host slows
// down for a while hands its last runs to the other instead of making the whole step wait for it at the
// region's end, and each thread still works on items next to its own (its caches, its Z-ordered neighbours).
// On 2-vCPU VMs whose vCPUs slow down one at a time for tens of milliseconds, the two threads' busy times in one
// pass differed by a factor 0.7-1.6 from step to step (docs/performance.md, twelfth session).
//
// Which thread computes an item never changes the bits: each item writes only its own results (a pair's line,
// a chunk's partial sums, a particle's state), and every sum over items is taken afterwards in item order.
// Claims are one atomic word per share (front and back packed), so a run is taken exactly once; the data the
// items write reach the other threads through the region's barriers, not through these atomics.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace fl {

// Where share t of nt starts in `count` items split statically: contiguous runs, the first count % nt one
// longer (as schedule(static) in libgomp and libomp).
inline std::size_t staticBegin(int t, int nt, std::size_t count) {
  const std::size_t q = count / static_cast<std::size_t>(nt), r = count % static_cast<std::size_t>(nt);
  const std::size_t k = static_cast<std::size_t>(t);
  return k * q + std::min(k, r);
}

class StealingRanges {
 public:
  // Serial, before the region: shares [bounds[t], bounds[t+1]) of bounds.size() - 1 threads (ascending, at most
  // 2^32 - 1 items), claimed in runs of `grain` items (>= 1).
  void reset(const std::vector<std::size_t>& bounds, std::size_t grain);
  // In the region, thread t: its next run [begin, end), from its own share's front, else from the back of the
  // share before it; false when both are empty (the thread is done with this loop).
  bool next(int t, std::size_t& begin, std::size_t& end);
  // The same two sources one at a time, for a loop that has work of its own between them (the contact pass's
  // seeds): its own share's front, then the back of the share before it. A thread that takes a run with
  // nextTaken reports it done with doneTaken once its items are written; the owner of a share, once nextOwn
  // has found it empty, may then wait for those runs (waitForTakers) and read what they wrote. Waits cannot
  // form a cycle: a thread takes runs only after its own wait.
  bool nextOwn(int t, std::size_t& begin, std::size_t& end);
  bool nextTaken(int t, std::size_t& begin, std::size_t& end);
  void doneTaken(int t, std::size_t items);
  void waitForTakers(int t) const;
  int threads() const { return m_threads; }
  // Serial, after the region: runs taken from another thread's share since the last reset.
  std::size_t stolen() const;

 private:
  // front (low 32 bits) and back (high 32 bits) of the unclaimed run of one share, on its own cache line
  struct alignas(64) Share {
    std::atomic<std::uint64_t> bounds{0};
    std::atomic<std::uint32_t> stolen{0};  // runs taken from its back, on the line the thief just took
    std::uint32_t end = 0;                 // the share's back at reset: the items taken are [back, end)
    std::atomic<std::uint64_t> takenDone{0};  // items of the runs taken that their thief has finished
  };
  int victimOf(int t) const { return (t + m_threads - 1) % m_threads; }
  bool claimFront(Share& s, std::size_t& begin, std::size_t& end) const;
  bool claimBack(Share& s, std::size_t& begin, std::size_t& end) const;

  std::unique_ptr<Share[]> m_shares;
  int m_capacity = 0, m_threads = 0;
  std::uint64_t m_grain = 1;
};

// Each thread's progress through its part of a round's shared input (the contact pass's halo slots,
// thread_boundary.hpp): the owner publishes how many of its items it has written so far, and a reader waits
// only until the items it is about to read are there, instead of every thread waiting at a barrier for the
// whole copy. A value of an earlier round never satisfies a wait, so the signals need no reset between rounds.
class RoundProgress {
 public:
  // Rounds run 1 .. roundsBeforeRestart - 1 (at most 2^32 - 1, so that a round and a count share one word), then
  // start again at 1 with the signals cleared (a test sets a small number).
  explicit RoundProgress(std::uint64_t roundsBeforeRestart = std::uint64_t{1} << 32)
      : m_restartAt(roundsBeforeRestart) {}
  // Serial, before the region: the next round, with a signal for each of `threads` threads on `cores`
  // processors (more threads than cores: a waiter soon yields its core, which the thread it waits for may need).
  std::uint64_t beginRound(int threads, int cores);
  // Thread t has written its first `done` items of `round` (release: the items are visible to a waiter).
  void publish(int t, std::uint64_t round, std::uint32_t done) {
    m_slots[t].value.store(round << 32 | done, std::memory_order_release);
  }
  // Wait until thread s has published at least `done` items of `round` (acquire); returns how many it has.
  std::uint32_t waitFor(int s, std::uint64_t round, std::uint32_t done) const;

 private:
  struct alignas(64) Slot {
    std::atomic<std::uint64_t> value{0};  // round << 32 | items written
  };
  std::unique_ptr<Slot[]> m_slots;
  int m_capacity = 0;
  int m_spins = 0;  // set by beginRound
  std::uint64_t m_restartAt;
  std::uint64_t m_round = 0;
};

// The runs one thread takes of a loop: for (std::size_t b, e; runs.next(b, e);) { ... items [b, e) ... }. From the
// ranges when they were set for a team of this size (of 2 or more), else its static share of `count` items,
// whole. A plain loop, not a callback: the step's loops inside lambdas ran ~10 % slower (docs/performance.md).
class ThreadRuns {
 public:
  ThreadRuns(StealingRanges& ranges, int t, int nt, std::size_t count)
      : m_ranges(nt > 1 && nt == ranges.threads() ? &ranges : nullptr), m_t(t),
        m_begin(staticBegin(t, nt, count)), m_end(staticBegin(t + 1, nt, count)) {}
  bool next(std::size_t& begin, std::size_t& end) {
    if (m_ranges) return m_ranges->next(m_t, begin, end);
    return nextStatic(begin, end);
  }
  // in two phases (StealingRanges::nextOwn): the static share has nothing to take and nobody to wait for
  bool nextOwn(std::size_t& begin, std::size_t& end) {
    if (m_ranges) return m_ranges->nextOwn(m_t, begin, end);
    return nextStatic(begin, end);
  }
  bool nextTaken(std::size_t& begin, std::size_t& end) { return m_ranges && m_ranges->nextTaken(m_t, begin, end); }
  void doneTaken(std::size_t items) {
    if (m_ranges) m_ranges->doneTaken(m_t, items);
  }
  void waitForTakers() const {
    if (m_ranges) m_ranges->waitForTakers(m_t);
  }

 private:
  bool nextStatic(std::size_t& begin, std::size_t& end) {
    if (m_begin >= m_end) return false;
    begin = m_begin, end = m_end;
    m_begin = m_end;
    return true;
  }
  StealingRanges* m_ranges;
  int m_t;
  std::size_t m_begin, m_end;
};

}  // namespace fl
