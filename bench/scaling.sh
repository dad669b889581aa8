#!/usr/bin/env bash
# Scaling of the step pipeline with the number of spheres (issue 6, item 3): the cached 4000-sphere dense
# packing at 318 kPa replicated 1, 8, 64 and 252 times (4k, 32k, 256k, 1.008M spheres; same density, stress
# and contacts per sphere), Z-ordered, run for a fixed number of particle-steps at each size; prints the
# time per particle-step, its ratio to the 4000-sphere one, the memory per particle and the 2-thread speed-up.
# Usage: bench/scaling.sh [--build DIR] [--threads 1,2] [--particle-steps 4e8]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build/perf"
threads="1,2"
psteps="4e8"
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --particle-steps) psteps="$2"; shift 2 ;;
    *) echo "scaling.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
bench="$build/bench/bench_dense"
if [ ! -x "$bench" ]; then
  cmake -S "$root" -B "$build" -DFL_BUILD_GUI=OFF -DFL_BUILD_TESTS=OFF -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" -j2 --target bench_dense >/dev/null
fi
cache="$root/build/bench-cache/dense4000_318kPa.state"  # shared with lammps_side_by_side.sh
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
printf '%-10s %-8s %14s %12s %10s %12s\n' "N" "threads" "p-steps/s" "ns/p-step" "vs 4k" "bytes/part."
declare -A base
for tile in 1,1,1 2,2,2 4,4,4 6,6,7; do
  IFS=, read -r a b c <<<"$tile"
  n=$((4000 * a * b * c))
  steps=$(awk -v p="$psteps" -v n="$n" 'BEGIN { s = int(p / n); if (s < 100) s = 100; print s }')
  repeats=3
  [ "$n" -gt 100000 ] && repeats=1
  (cd "$root" && "$bench" --cache "$cache" --tile "$tile" --threads "$threads" --steps "$steps" \
    --repeats "$repeats") >"$out/$n.txt" 2>&1 || { tail -20 "$out/$n.txt"; exit 1; }
  while read -r t rate ns bpp; do
    [ -z "${base[$t]:-}" ] && base[$t]="$ns"
    printf '%-10s %-8s %14s %12s %10.3f %12s\n' "$n" "$t" "$rate" "$ns" "$(awk -v a="$ns" -v b="${base[$t]}" 'BEGIN{print a/b}')" "$bpp"
  done < <(sed -n 's/^result: threads=\([0-9]*\) rate=\([^ ]*\) ns_per_particle_step=\([^ ]*\) N=[0-9]* bytes_per_particle=\([^ ]*\).*/\1 \2 \3 \4/p' "$out/$n.txt")
  grep -h "^speed-up" "$out/$n.txt" | sed "s/^/  N=$n: /" || true
done
