#!/usr/bin/env bash
# TSan of the GUI's worker/controller threads (issue 8, part 4), called by scripts/ci-reliability.sh.
# Builds tests/ui/sim_worker_test.cpp (target ui_sim_worker_test: SimWorker + snapshots on QtCore, no
# window, no VTK) with clang -fsanitize=thread and runs it: commands posted from the GUI thread and from a
# second thread, snapshot hand-over, pause/step/stop, errors, destruction of a running worker.
# What TSan sees: our code, the engine and the C++ library (std::thread/mutex/atomic: all of the worker's
# synchronisation). Debian's Qt is not instrumented, so races *inside* Qt are out of its view; the queued
# signal only carries a notification, the data travels through our mutex-protected shared_ptr.
# ignore_noninstrumented_modules=1: Qt's event objects are allocated on the worker (postEvent) and freed on
# the GUI thread after Qt's own futex-based lock, which TSan cannot see; without the option every queued
# signal is reported as a race on Qt's heap block (a false positive in Qt's frames, not in ours).
# The engine's OpenMP runs on LLVM libomp with the Archer tool, as in the core TSan stage.
# Env: FL_TSAN_BUILD_DIR (default build-tsan, the core TSan stage's folder: same flags, core built once), FL_JOBS (2).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="${FL_TSAN_BUILD_DIR:-$root/build-tsan}"  # shared with the core TSan stage of ci-reliability.sh
jobs="${FL_JOBS:-2}"
archer="$(ls /usr/lib/llvm-*/lib/libarcher.so 2>/dev/null | sort -V | tail -1 || true)"
if ! command -v clang++ >/dev/null || [ -z "$archer" ]; then
  echo "ci-gui-tsan: skipped: needs clang++ and libomp-dev (libarcher.so)"; exit 0
fi
mkdir -p "$dir"
CC=clang CXX=clang++ cmake -S "$root" -B "$dir" -DFL_BUILD_GUI=ON -DFL_BUILD_BENCH=OFF -DFL_BUILD_TESTS=ON \
  -DFL_SANITIZE=thread -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g -DNDEBUG" \
  >"$dir.configure.log" 2>&1 || { tail -30 "$dir.configure.log"; exit 1; }
cmake --build "$dir" -j "$jobs" --target ui_sim_worker_test >"$dir/build.log" 2>&1 || { tail -40 "$dir/build.log"; exit 1; }
QT_QPA_PLATFORM=offscreen OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive OMP_TOOL_LIBRARIES="$archer" \
  ARCHER_OPTIONS="verbose=0" \
  TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:ignore_noninstrumented_modules=1:suppressions=$root/tests/tsan.supp" \
  "$dir/tests/ui/ui_sim_worker_test" >"$dir/tsan.log" 2>&1 \
  || { grep -E "WARNING: ThreadSanitizer|FAILED|#[0-9]+ " "$dir/tsan.log" | head -60; exit 1; }
grep -E '^\[  PASSED' "$dir/tsan.log"
