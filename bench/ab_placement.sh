#!/usr/bin/env bash
# A/B of two bench_dense builds in back-to-back pairs, each pair classed by where the host had put the two
# vCPUs (docs/performance.md, ninth session): on this kind of VM a cache line between them takes either ~30 ns
# or ~170 ns, switching within seconds, and a 2-thread rate follows it. core_to_core is run before and after
# each pair; a pair is "near" when both probes are under 80 ns, "far" when both are over 120 ns, else "mixed"
# (the placement changed during the pair: its ratio means nothing). Prints the median B/A ratio of the pairs
# and the median rates per class, and whether both builds computed the same bits.
#
#   bench/ab_placement.sh BUILD_A BUILD_B [PAIRS=30] [STEPS=4000] [THREADS=2]
set -euo pipefail
a=${1:?usage: bench/ab_placement.sh BUILD_A BUILD_B [PAIRS] [STEPS] [THREADS]}
b=${2:?usage: bench/ab_placement.sh BUILD_A BUILD_B [PAIRS] [STEPS] [THREADS]}
pairs=${3:-30}
steps=${4:-4000}
threads=${5:-2}
here=$(cd "$(dirname "$0")/.." && pwd)
cache=${FL_BENCH_CACHE:-$here/build/bench-cache/dense4000_318kPa.state}
for d in "$a" "$b"; do
  [[ -x $d/bench/bench_dense ]] || { echo "bench/ab_placement.sh: no $d/bench/bench_dense" >&2; exit 2; }
done
probe=$a/bench/core_to_core
[[ -x $probe ]] || probe=$b/bench/core_to_core
[[ -x $probe ]] || { echo "bench/ab_placement.sh: no core_to_core in $a or $b (build that target)" >&2; exit 2; }
[[ -f $cache ]] || { echo "bench/ab_placement.sh: no cached packing $cache (run bench_dense once with --cache)" >&2; exit 2; }
line() { "$probe" 0 1 20000 | sed -n 's/.*one_way_ns=\([0-9.]*\).*/\1/p'; }
run() {  # build dir -> "rate fingerprint"
  "$1/bench/bench_dense" --threads "$threads" --steps "$steps" --repeats 1 --cache "$cache" 2>/dev/null |
    awk '/^result:/ { split($3, q, "="); r = q[2] } /^state fingerprint/ { f = $NF } END { print r, f }'
}
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for ((k = 1; k <= pairs; ++k)); do
  l1=$(line)
  if ((k % 2)); then ra=$(run "$a"); rb=$(run "$b"); else rb=$(run "$b"); ra=$(run "$a"); fi
  l2=$(line)
  echo "$l1 $l2 $ra $rb" >>"$log"
  echo "pair $k/$pairs: line $l1 / $l2 ns, A ${ra% *}, B ${rb% *}" >&2
done
echo "A = $a"
echo "B = $b"
echo "$pairs pairs, $steps steps, $threads thread(s); particle-steps/s"
awk 'NR == 1 { fa = $4; fb = $6 } $4 != fa || $6 != fb { diff = 1 }
     END { if (!diff && fa == fb) print "same bits: yes (state fingerprint " fa ")"; else print "same bits: NO" }' "$log"
awk '
  function med(arr, c,   i, j, t) {
    for (i = 2; i <= c; ++i) { t = arr[i]; for (j = i - 1; j > 0 && arr[j] > t; --j) arr[j + 1] = arr[j]; arr[j + 1] = t }
    return (c % 2) ? arr[(c + 1) / 2] : 0.5 * (arr[c / 2] + arr[c / 2 + 1])
  }
  { m = ($1 < 80 && $2 < 80) ? "near" : ($1 > 120 && $2 > 120) ? "far" : "mixed"
    c = ++n[m]; R[m, c] = $5 / $3; A[m, c] = $3; B[m, c] = $5 }
  END {
    printf "%-6s %6s %10s %14s %14s\n", "class", "pairs", "B/A", "A median", "B median"
    split("near far mixed", cls, " ")
    for (k = 1; k <= 3; ++k) {
      m = cls[k]; c = n[m]; if (!c) continue
      for (i = 1; i <= c; ++i) { r[i] = R[m, i]; x[i] = A[m, i]; y[i] = B[m, i] }
      printf "%-6s %6d %10.3f %14.4e %14.4e\n", m, c, med(r, c), med(x, c), med(y, c)
      delete r; delete x; delete y
    }
  }' "$log"
