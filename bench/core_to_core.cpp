// How long one cache line takes to travel between two cores of this machine (issue 6): two threads, pinned
// to the two CPUs given, hand a counter back and forth through one line; half the round trip is what a
// thread waits for a line the other core last wrote, e.g. a partner particle across the threads' boundary
// in the contact pass (docs/performance.md, "What two cores give").
//
//   core_to_core [CPU_A=0] [CPU_B=1] [ROUND_TRIPS=200000]
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace {
alignas(64) std::atomic<long> g_counter{0};

bool pinTo(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}
}  // namespace

int main(int argc, char** argv) {
  const int a = argc > 1 ? std::atoi(argv[1]) : 0;
  const int b = argc > 2 ? std::atoi(argv[2]) : 1;
  const long trips = argc > 3 ? std::atol(argv[3]) : 200000;
  if (trips < 1000) {
    std::fprintf(stderr, "core_to_core: ROUND_TRIPS must be >= 1000 (got %ld)\n", trips);
    return 2;
  }
  bool pinnedB = true;
  std::thread other([&] {
    pinnedB = pinTo(b);
    for (long k = 1; k < 2 * trips; k += 2) {  // answers every odd value with the next even one
      while (g_counter.load(std::memory_order_acquire) != k) {
      }
      g_counter.store(k + 1, std::memory_order_release);
    }
  });
  if (!pinTo(a)) {
    std::fprintf(stderr, "core_to_core: cannot pin to CPU %d\n", a);
    other.detach();
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < 2 * trips; k += 2) {
    g_counter.store(k + 1, std::memory_order_release);
    while (g_counter.load(std::memory_order_acquire) != k + 2) {
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  other.join();
  if (!pinnedB) {
    std::fprintf(stderr, "core_to_core: cannot pin to CPU %d\n", b);
    return 2;
  }
  const double ns = s / static_cast<double>(trips) * 1e9;
  std::printf("result: cpus=%d,%d round_trip_ns=%.1f one_way_ns=%.1f trips=%ld\n", a, b, ns, 0.5 * ns, trips);
  return 0;
}
