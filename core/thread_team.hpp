// The threads of the step's parallel loops (issue 6: the 2-thread speed-up).
//
// Each parallel loop of a step (drift, contact pass, kick, neighbour search) ran in an OpenMP region of its own.
// On the 2-vCPU VM with its vCPUs far apart (~220 ns a cache line between them) forking and joining a region
// cost ~3 µs (libgomp: the master waits at a dock for the woken thread, the join is a team barrier), twice a step:
// ~6 of the ~146 µs of a 2-thread 4000-sphere step, against ~0.6 µs a loop handed over through one cache line
// (docs/performance.md, twenty-seventh session). So Simulation::run holds its team in one OpenMP region for all
// its steps: thread 0 runs the steps, the other threads wait for each loop (a spin on one line, then asleep)
// and run it beside thread 0, whose wait for their ends is a count on another line. Outside a hold, each loop
// forks a region as before; with one thread it is a plain call.
//
// In a loop, OpenMP barriers and worksharing constructs bind to the held region, whose team is the loop's:
// the body is run by every thread of it in both cases. Nothing in a body may throw (house style: flag, report
// after); the driver of a hold may, and its exception leaves the hold after the team is released.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <vector>
#include <omp.h>

namespace fl {

class ThreadTeam {
 public:
  ThreadTeam();
  ~ThreadTeam();
  ThreadTeam(ThreadTeam&&) noexcept;
  ThreadTeam& operator=(ThreadTeam&&) noexcept;

  // Runs body(t, nt) on each thread t of nt: the held team's, or `threads` threads forked now (nt may be fewer,
  // as OpenMP gives). body(0, 1) is called directly for one thread.
  template <class Body>
  void each(int threads, const Body& body) {
    if (held() > 1) {
      dispatch(&call<Body>, &body);
    } else if (held() == 1 || threads <= 1) {
      body(0, 1);
    } else {
#pragma omp parallel num_threads(threads)
      body(omp_get_thread_num(), omp_get_num_threads());
    }
  }

  // Runs driver() on this thread, with `threads` threads held for the each() it calls (a hold inside a hold
  // is the outer one).
  template <class Driver>
  void hold(int threads, Driver&& driver) {
    if (threads <= 1 || held() != 0) {
      driver();
      return;
    }
    std::exception_ptr error;
    const std::uint64_t from = begin();
#pragma omp parallel num_threads(threads)
    {
      if (omp_get_thread_num() == 0) {
        enter(omp_get_num_threads());
        try {
          driver();
        } catch (...) {
          error = std::current_exception();
        }
        release();
      } else {
        serve(omp_get_thread_num(), from);
      }
    }
    if (error) std::rethrow_exception(error);
  }

  // The size of the held team (0: none held).
  int held() const;
  // The cores this process may run on: read once per hold while one is held, else asked now (omp_get_num_procs
  // is a system call, sched_getaffinity, ~0.36 µs when the threads are not bound).
  int cores() const;

 private:
  using Job = void (*)(const void* body, int t, int nt);
  template <class Body>
  static void call(const void* body, int t, int nt) {
    (*static_cast<const Body*>(body))(t, nt);
  }
  std::uint64_t begin() const;  // the job count a new hold starts from
  void enter(int threads);      // thread 0 of the held region
  void release();               // thread 0: the other threads leave
  void serve(int t, std::uint64_t from);  // the other threads: run each job until released
  void dispatch(Job job, const void* body);   // thread 0: the job on every thread, and back when all are done

  struct State;
  static void post(State& s);             // thread 0: a job, or the end of the hold
  std::unique_ptr<State> m_s;
};

// A maximum over the threads of a loop (an OpenMP max reduction): each thread puts its own into a line of its
// own, and the maximum is read after the loop. The same for any order of the threads.
class ThreadMax {
 public:
  void reset(int threads) { m_slots.assign(static_cast<std::size_t>(threads < 1 ? 1 : threads), Slot{}); }
  void put(int t, double v) { m_slots[static_cast<std::size_t>(t)].value = v; }
  double max() const {
    double m = 0.0;
    for (const Slot& s : m_slots) m = s.value > m ? s.value : m;
    return m;
  }

 private:
  struct alignas(64) Slot {
    double value = 0.0;
  };
  std::vector<Slot> m_slots;
};

}  // namespace fl
