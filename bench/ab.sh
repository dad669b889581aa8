#!/usr/bin/env bash
# Interleaved A/B of two bench_dense builds on the cached 4000-sphere packing (docs/performance.md, "Commands").
# On a shared VM one binary's rate moves by up to 2x between runs minutes apart, so the two builds are run in
# alternation, ROUNDS times each, and the script prints the median and the best rate of each per thread count.
# Noise from other tenants only ever slows a run, so the best of many short runs is the steadiest estimate;
# the upper quartile is printed beside it.
# With THREADS 1,2 it also prints each build's paired 2-thread speed-ups (each invocation's own ratio: median,
# range and how many reached issue 6's 1.8).
# It also says whether the two builds computed the same bits (bench_dense's state fingerprint; older builds
# without one print "none").
#
#   bench/ab.sh BUILD_A BUILD_B [ROUNDS=8] [STEPS=5000] [THREADS=1,2]
#   e.g. bench/ab.sh /tmp/base/build build 10
set -euo pipefail
a=${1:?usage: bench/ab.sh BUILD_A BUILD_B [ROUNDS] [STEPS] [THREADS]}
b=${2:?usage: bench/ab.sh BUILD_A BUILD_B [ROUNDS] [STEPS] [THREADS]}
rounds=${3:-8}
steps=${4:-5000}
threads=${5:-1,2}
here=$(cd "$(dirname "$0")/.." && pwd)
cache=${FL_BENCH_CACHE:-$here/build/bench-cache/dense4000_318kPa.state}
for d in "$a" "$b"; do
  [[ -x $d/bench/bench_dense ]] || { echo "bench/ab.sh: no $d/bench/bench_dense (build the bench_dense target)" >&2; exit 2; }
done
[[ -f $cache ]] || { echo "bench/ab.sh: no cached packing $cache (run bench_dense once with --cache)" >&2; exit 2; }
log=$(mktemp)
err=$(mktemp)
pairs=$(mktemp)
trap 'rm -f "$log" "$err" "$pairs"' EXIT
for ((r = 1; r <= rounds; ++r)); do
  # alternate which build goes first, so neither always runs right after the other
  if ((r % 2)); then order=("A:$a" "B:$b"); else order=("B:$b" "A:$a"); fi
  for entry in "${order[@]}"; do
    tag=${entry%%:*}
    dir=${entry#*:}
    out=$("$dir/bench/bench_dense" --threads "$threads" --steps "$steps" --repeats 1 --cache "$cache" 2>"$err") || {
      echo "bench/ab.sh: $dir/bench/bench_dense failed in round $r:" >&2
      cat "$err" >&2
      exit 1
    }
    fp=$(awk '/^state fingerprint/ { print $NF }' <<<"$out")
    if [[ $tag == A ]]; then fpA=$fp; else fpB=$fp; fi
    awk -v tag="$tag" '/^result:/ { split($2, t, "="); split($3, q, "="); print tag, t[2], q[2] }' <<<"$out" >>"$log"
    # the speed-up of this invocation (its 1- and 2-thread runs back to back, so both saw the same host)
    awk -v tag="$tag" '/^speed-up 2 vs 1 threads:/ { print tag, $NF }' <<<"$out" >>"$pairs"
  done
  echo "round $r/$rounds done" >&2
done
echo "A = $a"
echo "B = $b"
echo "rounds $rounds, $steps steps each; particle-steps/s"
if [[ -n ${fpA:-} && $fpA == "${fpB:-}" ]]; then
  echo "same bits: yes (state fingerprint $fpA in both)"
else
  echo "same bits: NO (state fingerprint A ${fpA:-none}, B ${fpB:-none})"
fi
# the median of the c sorted values v[key, 1..c] (both summaries below)
median='function median(v, key, c) { return (c % 2) ? v[key, (c + 1) / 2] : 0.5 * (v[key, c / 2] + v[key, c / 2 + 1]) }'
# the upper quartile too: between the best (one lucky run) and the median (half the runs slowed by the host)
printf '%-3s %-8s %12s %12s %12s\n' run threads median 'upper q.' best
sort -k1,1 -k2,2n -k3,3g "$log" | awk "$median"'
  { key = $1 " " $2; v[key, ++n[key]] = $3; if (!(key in seen)) { seen[key] = 1; keys[++nk] = key } }
  END {
    for (k = 1; k <= nk; ++k) {
      key = keys[k]; c = n[key]
      med = median(v, key, c)
      q = v[key, c - int(c / 4)]
      split(key, f, " ")
      printf "%-3s %-8s %12.4e %12.4e %12.4e\n", f[1], f[2], med, q, v[key, c]
    }
  }'
# paired speed-ups (only when THREADS holds 1 and 2): the median of each invocation's own ratio is steadier
# than the ratio of the medians, which mixes runs from different states of the host
if [[ -s $pairs ]]; then
  echo "2-thread speed-up of each invocation (2 vs 1 threads): median, min-max, runs >= 1.8"
  sort -k1,1 -k2,2g "$pairs" | awk "$median"'
    { v[$1, ++n[$1]] = $2; if (!($1 in seen)) { seen[$1] = 1; keys[++nk] = $1 } if ($2 >= 1.8) ++hit[$1] }
    END {
      for (k = 1; k <= nk; ++k) {
        t = keys[k]; c = n[t]
        printf "%-3s %12.3f   %.3f-%.3f   %d of %d\n", t, median(v, t, c), v[t, 1], v[t, c], hit[t] + 0, c
      }
    }'
fi
