#!/usr/bin/env bash
# What two cores of this machine give (issue 6, item 3: the 2-thread speed-up), measured in rounds:
#   - the time a cache line takes between the two cores (core_to_core: a thread waits that long for a line
#     the other core last wrote, e.g. a partner particle or a result across the threads' boundary),
#   - bench_dense on 1 thread pinned to CPU 0, then alone on CPU 1, then two copies at once (one per CPU):
#     two copies share nothing, so their summed rate over one copy's is the speed-up a code that shares
#     nothing between its threads could reach here,
#   - bench_dense on 2 threads, in the same round: the speed-up FabricLab reaches, and its share of that.
# Every round runs all of them back to back, so each is compared with the others at the same moment of a
# shared host whose speed moves by up to 35 % within minutes; medians over the rounds are printed.
#
# The medians are printed for all rounds and apart for the rounds with the vCPUs near and far apart.
#
#   bench/two_cores.sh [--build DIR] [--rounds 5] [--steps 5000]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/bench/common.sh"
build="$root/build/perf"
rounds=5
steps=5000
near_ns=80  # a round whose line takes less is "near" (the vCPUs share a cache)
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "two_cores.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ "$(nproc)" -ge 2 ] || { echo "two_cores.sh: needs 2 CPUs (nproc = $(nproc))" >&2; exit 2; }
build_bench "$root" "$build" bench_dense core_to_core
cache="$root/build/bench-cache/dense4000_318kPa.state"  # shared with lammps_side_by_side.sh
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
rate() {  # [taskset cpu|-] threads -> particle-steps/s of one run
  local pin=() ; [ "$1" != - ] && pin=(taskset -c "$1")
  (cd "$root" && "${pin[@]}" "$build/bench/bench_dense" --cache "$cache" --threads "$2" --steps "$steps" --repeats 1) |
    sed -n "s/^result: threads=$2 rate=\([^ ]*\).*/\1/p"
}
rate - 1 >/dev/null  # prepares the cached packing if missing
printf '%-6s %12s %12s %12s %12s %12s %10s %10s %9s\n' round "line [ns]" "1T cpu0" "1T cpu1" "both, cpu0" "both, cpu1" \
  "2 threads" "ceiling" "reached"
for ((r = 1; r <= rounds; ++r)); do
  line="$("$build/bench/core_to_core" 0 1 | sed -n 's/.*one_way_ns=\([^ ]*\).*/\1/p')"
  a0="$(rate 0 1)"; a1="$(rate 1 1)"
  rate 0 1 >"$out/b0" & rate 1 1 >"$out/b1"; wait
  b0="$(cat "$out/b0")"; b1="$(cat "$out/b1")"
  t2="$(rate - 2)"
  # ceiling: two unshared copies over one copy alone; reached: 2 threads over one thread alone
  awk -v r="$r" -v l="$line" -v a0="$a0" -v a1="$a1" -v b0="$b0" -v b1="$b1" -v t2="$t2" 'BEGIN {
    one = (a0 + a1) / 2; c = (b0 + b1) / one; s = t2 / one
    printf "%-6d %12.1f %12.4e %12.4e %12.4e %12.4e %10.4e %10.2f %9.2f\n", r, l, a0, a1, b0, b1, t2, c, s }' |
    tee -a "$out/rounds.txt"
done
col() { awk -v c="$1" '{print $c}' "$out/rounds.txt" | median | awk -v f="$2" '{printf f, $1}'; }
echo
echo "medians over $rounds rounds ($steps steps per run, 4000 spheres):"
echo "  one-way cache-line transfer between the cores: $(col 2 %.0f) ns"
echo "  1 thread: $(col 3 %.4e) (CPU 0), $(col 4 %.4e) (CPU 1) particle-steps/s"
echo "  two unshared 1-thread copies at once: $(col 5 %.4e) + $(col 6 %.4e) particle-steps/s"
echo "  speed-up two unshared copies reach (the ceiling): $(col 8 %.2f)"
echo "  FabricLab's 2-thread speed-up: $(col 9 %.2f) ($(col 7 %.4e) particle-steps/s)"
# the host moves the two vCPUs near (~30 ns a line, one cache) and far (~160-230 ns) apart within minutes, and the
# 2-thread step pays for every line it shares: the speed-up of each kind of round, apart
for kind in near far; do
  awk -v k="$kind" -v cut="$near_ns" '(k == "near") == ($2 < cut)' "$out/rounds.txt" >"$out/$kind.txt"
  n="$(wc -l <"$out/$kind.txt")"
  if [ "$n" -gt 0 ]; then
    echo "  $kind rounds (line $( [ "$kind" = near ] && echo "<" || echo ">=") $near_ns ns): $n, ceiling $(awk '{print $8}' "$out/$kind.txt" | median |
      awk '{printf "%.2f", $1}'), FabricLab $(awk '{print $9}' "$out/$kind.txt" | median | awk '{printf "%.2f", $1}')"
  fi
done
