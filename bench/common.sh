# What the benchmark scripts share (sourced by lammps_side_by_side.sh, lammps_scaling.sh, scaling.sh and two_cores.sh).

# median of the numbers on stdin, one per line
median() { sort -g | awk '{a[NR]=$1} END {if (NR%2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2}'; }

# build_bench ROOT BUILD TARGET...: a Release build without GUI and tests in BUILD, unless every target is built
build_bench() {
  local root="$1" build="$2" t missing=0
  shift 2
  for t in "$@"; do [ -x "$build/bench/$t" ] || missing=1; done
  [ "$missing" = 0 ] && return 0
  cmake -S "$root" -B "$build" -DFL_BUILD_GUI=OFF -DFL_BUILD_TESTS=OFF -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" -j2 --target "$@" >/dev/null
}

# the replicas of the cached 4000-sphere packing that scaling.sh and lammps_scaling.sh run (--tile NX,NY,NZ):
# 4k, 32k, 256k and 1.008M spheres, the same density, stress and contacts per sphere
scaling_tiles="1,1,1 2,2,2 4,4,4 6,6,7"
# tile_spheres TILE: spheres in the 4000-sphere packing replicated NX,NY,NZ times
tile_spheres() { local a b c; IFS=, read -r a b c <<<"$1"; echo $((4000 * a * b * c)); }
# run_steps PARTICLE_STEPS N MIN: the steps that make PARTICLE_STEPS at N spheres, at least MIN
run_steps() { awk -v p="$1" -v n="$2" -v m="$3" 'BEGIN { s = int(p / n); if (s < m) s = m; print s }'; }
