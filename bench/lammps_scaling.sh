#!/usr/bin/env bash
# FabricLab's and LAMMPS's scaling with the number of spheres on the same scenes, in pairs (issue 6, item 3).
#
#   bench/lammps_scaling.sh [--build DIR] [--threads 1,2] [--particle-steps 5e7] [--rounds 2]
#
# The cached 4000-sphere packing at 318 kPa (the side by side's) replicated 1, 8, 64 and 252 times, as
# bench/scaling.sh does (4k, 32k, 256k, 1.008M spheres: same density, stress and contacts per sphere), is
# exported as a LAMMPS data file at each size and run by both codes for the same number of particle-steps,
# back to back with the order alternating between rounds, thread t / rank r bound to core t / r (as in
# lammps_side_by_side.sh). Prints each code's time per particle-step, its ratio to its own 4000-sphere time
# (the scaling the issue asks to be within 1.3x), and FabricLab / LAMMPS at each size; checks that both codes
# see the same p and Z at step 0 at every size. The data files (~100 MB at 1M spheres) go to a temporary
# directory removed at the end.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/bench/common.sh"
. "$root/bench/lammps.sh"
build="$root/build/perf"
threads="1,2"
psteps="5e7"
rounds=2
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --particle-steps) psteps="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "lammps_scaling: unknown option $1" >&2; exit 2 ;;
  esac
done
die() { echo "lammps_scaling: FAIL: $*" >&2; exit 1; }

lmp_version="$(ensure_lammps)"
bench="$build/bench/bench_dense"
build_bench "$root" "$build" bench_dense
cache="$root/build/bench-cache/dense4000_318kPa.state"  # shared with lammps_side_by_side.sh and scaling.sh
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
t1="${threads%%,*}"  # the thread count whose LAMMPS log the step-0 check reads

echo "== the scenes: exported by bench_dense, the same physics written for LAMMPS $lmp_version =="
for tile in $scaling_tiles; do
  n="$(tile_spheres "$tile")"
  steps="$(run_steps "$psteps" "$n" 50)"
  "$bench" --cache "$cache" --tile "$tile" --export-lammps "$work/$n.data" --steps 1 --repeats 1 --threads 1 \
    >"$work/export$n.txt" 2>&1 || { tail -20 "$work/export$n.txt" >&2; die "bench_dense failed to export N=$n"; }
  line="$(grep '^export:' "$work/export$n.txt")" || die "bench_dense printed no export line for N=$n"
  echo "$line" >"$work/line$n.txt"
  write_lammps_input "$work/in$n" "$work/$n.data" "$line" "$steps"
  echo "N=$n: $steps steps per run"
done

fabriclab_ns() {  # N tile steps threads -> ns per particle-step of one run
  OMP_PLACES=cores OMP_PROC_BIND=close "$bench" --cache "$cache" --tile "$2" --steps "$3" --repeats 1 \
    --threads "$4" >"$work/fl.txt" 2>&1 || { tail -20 "$work/fl.txt" >&2; die "FabricLab failed on N=$1"; }
  sed -n "s/^result: threads=$4 rate=[^ ]* ns_per_particle_step=\([^ ]*\).*/\1/p" "$work/fl.txt"
}
lammps_ns() {  # N steps ranks -> ns per particle-step of one run
  local rate
  rate="$(lammps_rate "$work/in$1" "$3" "$1" "$2" "$work/lmp$1_$3.txt")"
  awk -v r="$rate" 'BEGIN {printf "%.3f\n", 1e9 / r}'
}
same_scene_at_step0() {  # N: both codes' p and Z at step 0 (LAMMPS's from its last run on $t1 ranks)
  local line lmp_p0 lmp_z0
  line="$(cat "$work/line$1.txt")"
  lmp_p0="$(sed -n 's/^STEP0 p=\([^ ]*\) .*/\1/p' "$work/lmp$1_$t1.txt")"
  lmp_z0="$(sed -n 's/^STEP0 .* Z=\(.*\)/\1/p' "$work/lmp$1_$t1.txt")"
  printf "  step 0, N=%s: FabricLab p %.6f Pa Z %.6f, LAMMPS p %.6f Pa Z %.6f\n" "$1" "$(export_field "$line" p0)" \
    "$(export_field "$line" Z0)" "$lmp_p0" "$lmp_z0"
  check_same_scene "$(export_field "$line" p0)" "$(export_field "$line" Z0)" "$lmp_p0" "$lmp_z0"
}

echo
echo "== rounds: at each size and thread count, FabricLab and LAMMPS back to back =="
: >"$work/runs.txt"  # N threads fabriclab_ns lammps_ns
for ((r = 1; r <= rounds; ++r)); do
  for tile in $scaling_tiles; do
    n="$(tile_spheres "$tile")"
    steps="$(run_steps "$psteps" "$n" 50)"
    for t in ${threads//,/ }; do
      if ((r % 2)); then fl="$(fabriclab_ns "$n" "$tile" "$steps" "$t")"; lm="$(lammps_ns "$n" "$steps" "$t")"
      else lm="$(lammps_ns "$n" "$steps" "$t")"; fl="$(fabriclab_ns "$n" "$tile" "$steps" "$t")"; fi
      [[ -n "$fl" && -n "$lm" ]] || die "no time for N=$n, $t thread(s)"
      printf "round %d: N=%-8s threads/ranks=%s  FabricLab %8.1f  LAMMPS %8.1f ns/p-step\n" "$r" "$n" "$t" "$fl" "$lm"
      echo "$n $t $fl $lm" >>"$work/runs.txt"
      # the same scene in both codes, checked at the first round rather than after all of them
      if ((r == 1)) && [[ "$t" == "$t1" ]]; then same_scene_at_step0 "$n"; fi
    done
  done
done

echo
printf "%-10s %-8s %14s %10s %14s %10s %14s\n" "N" "threads" "FabricLab ns" "vs 4k" "LAMMPS ns" "vs 4k" \
  "FL/LAMMPS rate"
declare -A fl4 lm4
sel() { awk -v n="$1" -v t="$2" -v c="$3" '$1 == n && $2 == t {print $c}' "$work/runs.txt"; }  # N threads column
for tile in $scaling_tiles; do
  n="$(tile_spheres "$tile")"
  for t in ${threads//,/ }; do
    fl="$(sel "$n" "$t" 3 | median)"; lm="$(sel "$n" "$t" 4 | median)"
    [[ -z "${fl4[$t]:-}" ]] && fl4[$t]="$fl" && lm4[$t]="$lm"
    printf "%-10s %-8s %14.1f %10.3f %14.1f %10.3f %14.2f\n" "$n" "$t" "$fl" \
      "$(awk -v a="$fl" -v b="${fl4[$t]}" 'BEGIN{print a/b}')" "$lm" \
      "$(awk -v a="$lm" -v b="${lm4[$t]}" 'BEGIN{print a/b}')" "$(awk -v a="$fl" -v b="$lm" 'BEGIN{print b/a}')"
  done
done
echo "(ns per particle-step, medians of $rounds rounds; 'vs 4k' is each code's own ratio to its 4000-sphere time)"
