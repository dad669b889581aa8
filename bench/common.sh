# What the benchmark scripts share (sourced by lammps_side_by_side.sh, scaling.sh and two_cores.sh).

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
