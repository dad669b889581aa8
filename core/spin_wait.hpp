// How a thread waits microseconds for another (work_stealing.hpp, thread_team.hpp).
#pragma once

#include <thread>

namespace fl {

constexpr int kSpins = 1 << 14;                  // the pauses before yielding, when the team fits on the cores
constexpr int kSpinsOversubscribed = 64;         // with more threads than cores (as libgomp's barriers do)

// One turn of a wait for another thread: a pause for the first `spins` turns (the waits last microseconds), then
// the core given away, which the awaited thread may need when there are more threads than cores.
inline void backOff(int turn, int spins) {
  if (turn < spins) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  } else {
    std::this_thread::yield();
  }
}

// The pauses before yielding for a team of `threads` threads on `cores` processors.
constexpr int spinsFor(int threads, int cores) { return threads > cores ? kSpinsOversubscribed : kSpins; }

}  // namespace fl
