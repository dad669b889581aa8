#!/usr/bin/env bash
# Bounded libFuzzer pass over the readers that face hand-written files (issue 8):
#   fuzz_scene_json   parseScene on arbitrary JSON        fuzz_scene_file  loadScene on arbitrary bytes
#   fuzz_packing_csv  readPackingCsv                      fuzz_lammps      readLammpsData
#   fuzz_checkpoint   Runner::fromCheckpoint (raw file, or payload re-framed with a valid checksum)
# Builds tests/fuzz with clang (ASan + UBSan + libFuzzer) in its own folder, writes the seed corpus (shipped
# scenes, a checkpoint/CSV/LAMMPS export of a tiny run), runs each target for SECONDS, prints executions per
# target. Fails if any target finds a crash, hang (> 10 s per input), leak, sanitizer report or a broken
# contract (an exception other than fl::InputError/IoError, a message without the file name, ...);
# the reproducer is kept in $FL_FUZZ_BUILD/artifacts/ (replay: <target> <file>).
# Usage: scripts/fuzz.sh [seconds-per-target]    (default 60; env FL_FUZZ_BUILD, default /tmp/rel-fuzz;
#        FL_FUZZ_TARGETS to pick targets, e.g. "fuzz_lammps fuzz_checkpoint"; FL_FUZZ_PREBUILT=1: the targets
#        are already built in FL_FUZZ_BUILD, e.g. build-asan/tests/fuzz of CI's ASan build with FL_FUZZ=ON)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
secs="${1:-60}"
build="${FL_FUZZ_BUILD:-/tmp/rel-fuzz}"
targets=(${FL_FUZZ_TARGETS:-fuzz_scene_json fuzz_scene_file fuzz_packing_csv fuzz_lammps fuzz_checkpoint})

command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang libclang-rt-14-dev libomp-14-dev)"; exit 1; }
if [ -n "${FL_FUZZ_PREBUILT:-}" ]; then
  for t in "${targets[@]}" fuzz_make_seeds; do
    [ -x "$build/$t" ] || { echo "fuzz.sh: FL_FUZZ_PREBUILT is set but $build/$t is not built"; exit 1; }
  done
else
  if [ ! -f "$build/CMakeCache.txt" ]; then
    CXX=clang++ cmake -S "$root/tests/fuzz" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  fi
  cmake --build "$build" -j "${FL_JOBS:-2}" >"$build/build.log" 2>&1 || { tail -40 "$build/build.log"; exit 1; }
fi

# Seed corpus: shipped scenes (JSON with comments), generated checkpoint / CSV / LAMMPS files.
seeds="$build/seeds"
rm -rf "$seeds"
mkdir -p "$seeds/scene"
cp "$root"/resources/scenes/*.json "$seeds/scene/"
[ -d "$root/tests/data" ] && find "$root/tests/data" -name '*.json' -exec cp {} "$seeds/scene/" \; || true
ASAN_OPTIONS=detect_leaks=1 "$build/fuzz_make_seeds" "$seeds" >/dev/null
declare -A seed=([fuzz_scene_json]=scene [fuzz_scene_file]=scene [fuzz_packing_csv]=csv [fuzz_lammps]=lammps
                 [fuzz_checkpoint]=checkpoint)
declare -A dict=([fuzz_scene_json]=scene.dict [fuzz_scene_file]=scene.dict [fuzz_packing_csv]=packing.dict
                 [fuzz_lammps]=packing.dict)
declare -A maxlen=([fuzz_checkpoint]=65536)

mkdir -p "$build/artifacts"
summary="$build/fuzz-summary.txt"
printf "%-18s %8s %12s %10s %8s %s\n" target seconds executions exec/s corpus result | tee "$summary"
status=0
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  mkdir -p "$corpus"
  args=(-max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len="${maxlen[$t]:-16384}"
        -print_final_stats=1 -artifact_prefix="$build/artifacts/$t-")
  [ -n "${dict[$t]:-}" ] && args+=(-dict="$root/tests/fuzz/${dict[$t]}")
  log="$build/$t.log"
  result=ok
  # UBSan findings abort (the standalone build has no recovery; CI's ASan build's core recovers unless told to
  # halt); LeakSanitizer on.
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 OMP_NUM_THREADS=1 \
    "$build/$t" "${args[@]}" "$corpus" "$seeds/${seed[$t]}" >"$log" 2>&1 || { result=FAILED; status=1; }
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  units=$(ls "$corpus" | wc -l)
  printf "%-18s %8s %12s %10s %8s %s\n" "$t" "$secs" "$execs" "$(( execs / (secs > 0 ? secs : 1) ))" "$units" \
    "$result" | tee -a "$summary"
  if [ "$result" != ok ]; then
    grep -E "ERROR|CONTRACT|runtime error|SUMMARY|Test unit written|#[0-9]+ 0x" "$log" | head -30 || true
  fi
done
exit $status
