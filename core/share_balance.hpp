// How large each thread's share of the step is (issue 6: the 2-thread speed-up on shared hosts).
//
// The threads' shares (thread_boundary.hpp) were equal numbers of pair chunks, and each thread kicks the particles
// whose pairs it computes as first particle. Two things make equal chunks slow:
//  - the vCPUs of the 2-vCPU VMs we measure on are not always equally fast: in the twenty-sixth session one ran
//    the 4000-sphere step at 87 ns per particle-step and the other at 63 ns, for minutes (each pinned alone;
//    docs/performance.md), and the kick after a pass with the halo and seeds takes no runs from another share, so
//    the step waited for the slow core's half;
//  - equal chunks are not equal particles: in Z-order the last particles list fewer pairs as first particle, so
//    at 4000 spheres the second thread kicked ~15 % more particles than the first.
// So the edges follow the measured costs: every thread times its own part of the contact pass and of the kick and
// counts its items (pair chunks, particles); every kWindowSteps steps the window's seconds per chunk and per
// particle of each thread (smoothed across windows) predict the step's time for any edges, as the slower
// thread's pass plus the slower thread's kick (a barrier lies between them), and the edges that minimise it are
// taken when they are predicted at least kMinGain faster than the current ones (so that noise does not move them
// back and forth: one chunk is ~2 % of the pairs at 4000 spheres, and an edge three chunks off cost ~11 %).
//
// Which thread computes a chunk or kicks a particle never changes the bits (thread_boundary.hpp,
// work_stealing.hpp), so the edges change only the time: tests/determinism_test.cpp runs skewed fixed shares
// against one thread.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace fl {

// One thread's times and items over a window: the contact pass's chunks and the kick's particles.
struct ThreadWork {
  double passSeconds = 0.0, kickSeconds = 0.0;
  double passItems = 0.0, kickItems = 0.0;
};

// What one item costs a thread [s]: a chunk of the pass, a particle of the kick.
struct ThreadCosts {
  double perChunk = 0.0, perParticle = 0.0;
};

// The predicted time of a step whose shares begin at chunks `edges` (threads + 1 entries, the last the chunk
// count), where chunk k's first particle is firstParticle[k] (chunks + 1 entries, the last the particle count):
// the slowest thread's pass plus the slowest thread's kick [s].
double predictedStep(const std::vector<ThreadCosts>& cost, const std::vector<std::size_t>& edges,
                     const std::vector<std::size_t>& firstParticle);

// The edges that minimise predictedStep, every thread keeping at least one chunk: all of them tried for two
// threads, else edges moved one chunk at a time from `start` while that helps.
std::vector<std::size_t> bestEdges(const std::vector<ThreadCosts>& cost, const std::vector<std::size_t>& firstParticle,
                                   std::vector<std::size_t> start);

// Where each thread's chunks begin for fixed shares `w` (threads + 1 entries, the last `chunks`): the nearest
// chunk to each cumulative share, every thread keeping at least one chunk. No shares give staticBegin's split.
std::vector<std::size_t> chunkBeginFor(const std::vector<double>& w, int threads, std::size_t chunks);

class ShareBalance {
 public:
  static constexpr long kWindowSteps = 128;  // ~20 ms a window at 4000 spheres on 2 threads
  static constexpr double kMinGain = 0.02;   // predicted gain of new edges before they are taken
  static constexpr double kSmoothing = 0.5;  // weight of the newest window in the costs

  // Fixed shares instead of measured ones (tests, bench_dense --shares even): empty for equal shares.
  void fix(std::vector<double> shares);
  void measure();  // back to measured shares (the default)
  bool measuring() const { return m_measuring; }

  // Serial: slots for a team of `threads` (a new team size starts a new estimate), and the edges for a boundary
  // of `threads` shares whose chunk k begins at particle firstParticle[k]: the fixed shares', the best for the
  // measured costs, or equal ones before the first window.
  void prepare(int threads);
  std::vector<std::size_t> edges(int threads, const std::vector<std::size_t>& firstParticle) const;

  // In a region, thread t (each writes its own slot): its own work in this step's pass and kick.
  void addPass(int t, double seconds, std::size_t chunks) {
    m_slots[t].work.passSeconds += seconds;
    m_slots[t].work.passItems += static_cast<double>(chunks);
  }
  void addKick(int t, double seconds, std::size_t particles) {
    m_slots[t].work.kickSeconds += seconds;
    m_slots[t].work.kickItems += static_cast<double>(particles);
  }
  // Serial, after a step's kick: true when a window has ended (then call reconsider).
  bool endStep() { return m_measuring && m_threads > 1 && ++m_steps >= kWindowSteps; }
  // Serial: the window's costs folded in; true when edges() would now be kMinGain faster than `current`.
  bool reconsider(const std::vector<std::size_t>& current, const std::vector<std::size_t>& firstParticle);
  const std::vector<ThreadCosts>& costs() const { return m_cost; }  // empty before the first window

 private:
  struct alignas(64) Slot {
    ThreadWork work;
  };
  std::unique_ptr<Slot[]> m_slots;
  int m_threads = 0;
  long m_steps = 0;
  bool m_measuring = true;
  std::vector<double> m_fixed;       // fixed shares; empty: equal
  std::vector<ThreadCosts> m_cost;   // measured, smoothed; empty before the first window
};

}  // namespace fl
