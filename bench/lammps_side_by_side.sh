#!/usr/bin/env bash
# FabricLab vs LAMMPS on the same dense packing, in one invocation (issue 6).
#
#   bench/lammps_side_by_side.sh [--steps N] [--repeats N] [--build DIR] [--out DIR]
#
# 1. installs Debian's `lammps` if missing (idempotent; never yade or paraview: they remove libvtk9-dev),
# 2. builds bench_dense (cmake, no GUI) in --build (default build/perf) unless it is already built,
# 3. bench_dense prepares or loads the cached 4000-sphere packing at p' = 318 kPa, exports it as a LAMMPS
#    data file (core/packing_io.hpp writeLammpsData) and checks that 1 and 2 threads give the same bits,
# 4. writes the LAMMPS input for the same physics — Hertz with E* from E and nu (hertz/material), Mindlin
#    no-slip tangential spring k_t = 8 G* a (tangential mindlin NULL), Coulomb mu = 0.235, no damping
#    (eta_n0 = 0, x_gamma_t = 0), no rolling or twisting, newton on, fix nve/sphere, same dt, same steps,
#    same skin,
# 5. measures in pairs: each repeat runs FabricLab and LAMMPS back to back (the order alternating between
#    repeats), for 1 thread vs 1 rank and 2 threads vs 2 ranks, so both codes of a pair see the same state
#    of the host (on the shared 2-core VMs the speed of each core moves by up to 35 % within minutes), and
#    both are bound alike: Open MPI binds rank r to core r (--bind-to core, its default for 2 ranks or
#    fewer), and FabricLab's thread t goes to core t (OMP_PLACES=cores OMP_PROC_BIND=close); unbound, the
#    1-thread run could land on a core in a slow period while LAMMPS's one rank always runs on core 0,
# 6. checks that both see the same p and coordination number Z = 2C/N at step 0 (fails beyond 1 %),
# 7. prints every pair's particle-steps/s and ratio FabricLab / LAMMPS, then the medians and the spread.
# LAMMPS's time is its "Loop time" (the run only, no setup); FabricLab's is bench_dense's, also the run only.
set -euo pipefail

steps=20000
repeats=5
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/bench/common.sh"
. "$root/bench/lammps.sh"
build="$root/build/perf"
out="$root/build/bench-cache"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --steps) steps="$2"; shift 2 ;;
    --repeats) repeats="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) echo "lammps_side_by_side: unknown option $1" >&2; exit 2 ;;
  esac
done

die() { echo "lammps_side_by_side: FAIL: $*" >&2; exit 1; }

# ---- 1. LAMMPS --------------------------------------------------------------------------------------
lmp_version="$(ensure_lammps)"

# ---- 2.-3. FabricLab ---------------------------------------------------------------------------------
bench="$build/bench/bench_dense"
build_bench "$root" "$build" bench_dense
mkdir -p "$out"
data="$out/dense4000_318kPa.data"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

echo "== FabricLab ($bench): the scene, the export and the thread-count check =="
"$bench" --cache "$out/dense4000_318kPa.state" --export-lammps "$data" --steps 200 --repeats 1 \
  --threads 1,2 | tee "$work/fabriclab.txt"
grep -q '^final positions bit-identical across thread counts: yes' "$work/fabriclab.txt" ||
  die "FabricLab's 1- and 2-thread runs differ"
export_line="$(grep '^export:' "$work/fabriclab.txt")" || die "bench_dense printed no export line"
N="$(export_field "$export_line" N)"; fl_p0="$(export_field "$export_line" p0)"; fl_z0="$(export_field "$export_line" Z0)"

# ---- 4. LAMMPS --------------------------------------------------------------------------------------
write_lammps_input "$work/in.dense" "$data" "$export_line" "$steps"

# ---- 5. the pairs ----------------------------------------------------------------------------------
fabriclab_rate() {  # threads -> particle-steps/s of one run, thread t on core t like MPI's rank r on core r
  OMP_PLACES=cores OMP_PROC_BIND=close "$bench" --cache "$out/dense4000_318kPa.state" --steps "$steps" --repeats 1 --threads "$1" >"$work/fl$1.txt" ||
    { cat "$work/fl$1.txt" >&2; die "FabricLab failed on $1 thread(s)"; }
  sed -n "s/^result: threads=$1 rate=\([^ ]*\).*/\1/p" "$work/fl$1.txt"
}
echo
echo "== pairs: FabricLab and LAMMPS $lmp_version back to back, $steps steps each =="
printf "%-7s %-20s %14s %14s %8s\n" "repeat" "threads / ranks" "FabricLab" "LAMMPS" "ratio"
: >"$work/pairs.txt"
for ((k = 1; k <= repeats; ++k)); do
  for t in 1 2; do
    if ((k % 2)); then fl="$(fabriclab_rate "$t")"; lm="$(lammps_rate "$work/in.dense" "$t" "$N" "$steps" "$work/lmp$t.txt")"
    else lm="$(lammps_rate "$work/in.dense" "$t" "$N" "$steps" "$work/lmp$t.txt")"; fl="$(fabriclab_rate "$t")"; fi
    ratio="$(awk -v a="$fl" -v b="$lm" 'BEGIN {printf "%.4f", a / b}')"
    printf "%-7s %-20s %14.4e %14.4e %8.2f\n" "$k" "$t / $t" "$fl" "$lm" "$ratio"
    echo "$t $fl $lm $ratio" >>"$work/pairs.txt"
  done
done
cp "$work/lmp1.txt" "$out/lammps_1rank.log"
cp "$work/lmp2.txt" "$out/lammps_2ranks.log"
lmp_p0="$(sed -n 's/^STEP0 p=\([^ ]*\) .*/\1/p' "$work/lmp1.txt")"
lmp_z0="$(sed -n 's/^STEP0 .* Z=\(.*\)/\1/p' "$work/lmp1.txt")"
lmp_end="$(grep '^END' "$work/lmp1.txt")"
echo "LAMMPS after $steps steps (1 rank): $lmp_end"
echo "FabricLab after $steps steps (1 thread): $(grep "^after $steps steps" "$work/fl1.txt")"

# ---- 6. same scene? ---------------------------------------------------------------------------------
echo
printf "step 0          %16s %16s\n" "FabricLab" "LAMMPS"
printf "  p [Pa]        %16.6f %16.6f\n" "$fl_p0" "$lmp_p0"
printf "  Z = 2C/N      %16.6f %16.6f\n" "$fl_z0" "$lmp_z0"
check_same_scene "$fl_p0" "$fl_z0" "$lmp_p0" "$lmp_z0"

# ---- 7. the numbers ---------------------------------------------------------------------------------
echo
col() { awk -v t="$1" -v c="$2" '$1 == t {print $c}' "$work/pairs.txt"; }
printf "%-22s %16s %16s %8s %16s %6s\n" "particle-steps/s" "FabricLab" "LAMMPS" "ratio" "ratio min-max" ">= 2"
for t in 1 2; do
  label="$t thread(s) / $t rank(s)"
  fl="$(col "$t" 2 | median)"; lm="$(col "$t" 3 | median)"; r="$(col "$t" 4 | median)"
  lo="$(col "$t" 4 | sort -g | head -1)"; hi="$(col "$t" 4 | sort -g | tail -1)"
  above="$(col "$t" 4 | awk '$1 >= 2 {++n} END {printf "%d/%d", n, NR}')"
  printf "%-22s %16.4e %16.4e %8.2f %16s %6s\n" "$label" "$fl" "$lm" "$r" "$lo-$hi" "$above"
done
echo "(N = $N, $steps steps; rates and ratio are medians over $repeats pairs, the ratio the median of each pair's"
echo " ratio; logs in $out)"
