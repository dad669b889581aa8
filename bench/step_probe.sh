#!/usr/bin/env bash
# The step's phase probe (issue 6: where the 2-thread step's time goes; docs/performance.md, thirtieth session).
#
#   bench/step_probe.sh [--build DIR] [-- BENCH_DENSE_ARGS...]
#
# Copies the committed tree (git archive HEAD) into DIR/src, applies bench/step_probe.patch there (TSC counters
# around each thread's contact pass and kick, the halo copy and its waits, the wait for the runs other threads
# took, the seeds' sum, each chunk of the pass, the team's hand-overs; the patch's core/probe.hpp lists them),
# builds bench_dense in DIR/build and runs it with FL_PROBE=1, threads bound to cores, and the given arguments
# (default: --threads 1,2 --steps 2000 --interleave 8, so that 1 and 2 threads alternate). At exit it prints, per
# team size, each thread's microseconds per step in each slot. The engine in the tree is never changed.
# Switches of the patched build: FL_PROBE_BAL=1 logs each window of the share balance (its costs and best edge),
# FL_FORCE_HALO=1 runs the pass's halo template on one thread, FL_NO_STEAL=1 takes no runs in a seeded pass.
# The patch was made against the engine of the thirtieth session (c061aa0) and made again in the forty-second (the
# seeds' sum from ThreadBoundary::seedEntry); once the engine moves on it may no longer apply: the script then says
# so and stops, and the patch is to be made again from its description.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="$root/build/probe"
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build) dir="$2"; shift 2 ;;
    --) shift; args=("$@"); break ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "step_probe.sh: unknown option $1 (bench_dense's arguments go after --)" >&2; exit 2 ;;
  esac
done
[ ${#args[@]} -gt 0 ] || args=(--threads 1,2 --steps 2000 --interleave 8)
head=$(git -C "$root" rev-parse HEAD)
# a new copy only when HEAD moved, so that an unchanged tree is not rebuilt
if [ "$(cat "$dir/src.commit" 2>/dev/null)" != "$head" ]; then
  rm -rf "$dir/src"
  mkdir -p "$dir/src"
  git -C "$root" archive HEAD | tar -x -C "$dir/src"
  if ! patch -p1 -d "$dir/src" --dry-run --silent < "$root/bench/step_probe.patch" >/dev/null; then
    echo "step_probe.sh: bench/step_probe.patch no longer applies to $head; make it again" \
         "(docs/performance.md, thirtieth session, says what it times)" >&2
    exit 1
  fi
  patch -p1 -d "$dir/src" --silent < "$root/bench/step_probe.patch"
  echo "$head" > "$dir/src.commit"
fi
cmake -S "$dir/src" -B "$dir/build" -DFL_BUILD_GUI=OFF -DFL_BUILD_TESTS=OFF -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$dir/build" -j2 --target bench_dense >/dev/null
cd "$root"  # bench_dense's default packing cache is build/bench-cache/ here
FL_PROBE=1 OMP_PLACES=cores OMP_PROC_BIND=close "$dir/build/bench/bench_dense" "${args[@]}"
