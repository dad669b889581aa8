#!/usr/bin/env bash
# Scaling of the step pipeline with the number of spheres (issue 6, item 3): the cached 4000-sphere dense
# packing at 318 kPa replicated 1, 8, 64 and 252 times (4k, 32k, 256k, 1.008M spheres; same density, stress
# and contacts per sphere), Z-ordered, run for a fixed number of particle-steps at each size; prints the
# time per particle-step, its ratio to the 4000-sphere one, the memory per particle and the 2-thread speed-up.
# The sizes are swept --rounds times and the medians are printed: the speed of this kind of shared VM moves by up
# to 35 % within minutes, and a sweep done once compares the sizes at different moments of it. The ratio of the
# best runs is printed too: the host's noise only ever slows a run. Each round runs 4k before every larger size
# (4k 32k 4k 256k 4k 1M, and one 4k run after the last round), so each larger run also has a paired ratio: its
# time over the mean of the 4k runs just before and after it, which cancels the host's slower drifts; the
# column "paired" gives their median and range. Every run uses the skin the automatic skin settles to on the
# 4000-sphere packing (bench_dense --skin settled): the 1M-sphere run has only ~100 steps, too few to settle.
# Usage: bench/scaling.sh [--build DIR] [--threads 1,2] [--particle-steps 2e8] [--rounds 3]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/bench/common.sh"
build="$root/build/perf"
threads="1,2"
psteps="2e8"
rounds=3
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --particle-steps) psteps="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    *) echo "scaling.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
bench="$build/bench/bench_dense"
build_bench "$root" "$build" bench_dense
cache="$root/build/bench-cache/dense4000_318kPa.state"  # shared with lammps_side_by_side.sh
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
: >"$out/runs.txt"  # sequence N threads rate ns bytes, one line per run and thread count
seq=0
# run_size TILE ROUND: one bench_dense run of the tile, appended to runs.txt as run number $seq
run_size() {
  local n steps
  n="$(tile_spheres "$1")"
  steps="$(run_steps "$psteps" "$n" 100)"
  seq=$((seq + 1))
  (cd "$root" && "$bench" --cache "$cache" --tile "$1" --threads "$threads" --steps "$steps" \
    --skin settled --repeats 1) >"$out/$n.txt" 2>&1 || { tail -20 "$out/$n.txt"; exit 1; }
  sed -n "s/^result: threads=\([0-9]*\) rate=\([^ ]*\) ns_per_particle_step=\([^ ]*\) N=[0-9]* bytes_per_particle=\([^ ]*\).*/$seq $n \1 \2 \3 \4/p" \
    "$out/$n.txt" | tee -a "$out/runs.txt" | awk -v r="$2" '{printf "round %d: N=%s threads=%s %s ns/p-step\n", r, $2, $3, $5}'
}
base_tile="${scaling_tiles%% *}"
for ((r = 1; r <= rounds; ++r)); do
  for tile in ${scaling_tiles#* }; do
    run_size "$base_tile" "$r"
    run_size "$tile" "$r"
  done
done
run_size "$base_tile" "$rounds"
echo
# paired ratios: "N threads ratio" for every larger run, over the mean of the 4000-sphere runs before and after it
awk '{ n[$1, $3] = $2; ns[$1, $3] = $5; th[$3] = 1; if ($1 > last) last = $1 }
     END { for (t in th) for (s = 1; s <= last; ++s) if (((s, t) in n) && n[s, t] != 4000) {
             for (p = s - 1; p >= 1 && !(((p, t) in n) && n[p, t] == 4000); --p) ;
             for (q = s + 1; q <= last && !(((q, t) in n) && n[q, t] == 4000); ++q) ;
             if (p >= 1 && q <= last) print n[s, t], t, ns[s, t] / (0.5 * (ns[p, t] + ns[q, t])) } }' \
  "$out/runs.txt" >"$out/paired.txt"
printf '%-10s %-8s %14s %12s %10s %16s %12s %18s %12s\n' "N" "threads" "p-steps/s" "ns/p-step" "vs 4k" "ns min-max" \
  "best vs 4k" "paired (min-max)" "bytes/part."
declare -A base best ns1
for tile in $scaling_tiles; do
  n="$(tile_spheres "$tile")"
  for t in ${threads//,/ }; do
    sel() { awk -v n="$n" -v t="$t" -v c="$1" '$2 == n && $3 == t {print $c}' "$out/runs.txt"; }
    rate="$(sel 4 | median)"; ns="$(sel 5 | median)"; bpp="$(sel 6 | head -1)"
    lo="$(sel 5 | sort -g | head -1)"; hi="$(sel 5 | sort -g | tail -1)"
    [ -z "${base[$t]:-}" ] && base[$t]="$ns" && best[$t]="$lo"
    [ "$t" = 1 ] && ns1[$n]="$ns"
    paired="-"
    if [ "$n" != 4000 ]; then
      pr="$(awk -v n="$n" -v t="$t" '$1 == n && $2 == t {print $3}' "$out/paired.txt")"
      paired="$(printf '%.3f (%.2f-%.2f)' "$(median <<<"$pr")" "$(sort -g <<<"$pr" | head -1)" \
        "$(sort -g <<<"$pr" | tail -1)")"
    fi
    printf '%-10s %-8s %14.4e %12.1f %10.3f %16s %12.3f %18s %12s\n' "$n" "$t" "$rate" "$ns" \
      "$(awk -v a="$ns" -v b="${base[$t]}" 'BEGIN{print a/b}')" "$lo-$hi" \
      "$(awk -v a="$lo" -v b="${best[$t]}" 'BEGIN{print a/b}')" "$paired" "$bpp"
    if [ "$t" = 2 ] && [ -n "${ns1[$n]:-}" ]; then
      awk -v a="${ns1[$n]}" -v b="$ns" -v n="$n" 'BEGIN {printf "  N=%s: 2-thread speed-up %.2f (of the medians)\n", n, a / b}'
    fi
  done
done
echo "(medians of $rounds rounds, $psteps particle-steps per run; the 4000-sphere medians over all its runs)"
