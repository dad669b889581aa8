#!/usr/bin/env bash
# Runs the paper's whole study at full size: both specimens, the four consolidation histories and the
# eight cyclic runs of Table 2, reusing whatever is already prepared in out/paper/ (a step whose stages.json
# lists all its stages is skipped). A step that nothing else can run beside (a specimen, the anisotropic
# history) takes JOBS threads; the others run JOBS at a time, one thread each. Results do not depend on the
# thread count (the same bits, tests/determinism_test.cpp).
# Usage: scripts/paper-study.sh [JOBS]       (14 min on 2 AMD EPYC cores, 21-23 min on Zen 4 before the M–D law was vectorised; docs/performance.md)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
jobs="${1:-$(nproc)}"
bin="${FL_BUILD_DIR:-$root/build}/app/fabriclab-run"
[ -x "$bin" ] || "$root/scripts/build.sh" -DFL_BUILD_GUI=OFF
scenes="$root/resources/scenes/paper"

done_already() {  # scene name -> true if its results folder holds a complete stages.json
  local out="$root/out/paper/$1" want
  want=$(grep -c '"type"' "$scenes/$1.json")
  [ -f "$out/stages.json" ] && [ "$(grep -c '"type"' "$out/stages.json")" -ge "$want" ]
}
run_one() {  # scene name [threads, default 1]
  local name="$1" threads="${2:-1}"
  if done_already "$name"; then echo "== $name: already done"; return 0; fi
  echo "== $name: running on $threads thread(s)"
  "$bin" "$scenes/$name.json" --threads "$threads" --overwrite --quiet > "$root/out/paper/$name.log" 2>&1 \
    && echo "== $name: done" || { echo "== $name: FAILED (see out/paper/$name.log)"; return 1; }
}
export -f run_one done_already
export root bin scenes
mkdir -p "$root/out/paper"

# A failed step does not stop the others that do not need it, nor the report (which lists it as not run);
# the script's exit status is then 1.
failed=0
run_one specimen-isotropic "$jobs" || failed=1
printf '%s\n' history-isotropic-isotropic history-isotropic-k0 history-isotropic-ocr |
  xargs -P "$jobs" -I{} bash -c 'run_one {}' || failed=1
run_one specimen-anisotropic "$jobs" || failed=1
run_one history-anisotropic-isotropic "$jobs" || failed=1
# The cyclic runs, longest first: the Mindlin–Deresiewicz runs (run-*-md, ~2x a no-slip run's time), then the
# others by name. Replayed with the eleventh session's run times (docs/performance.md) the two lanes finish
# the runs in 1160 s this way against 1213 s by name alone (the tenth session's times, before the servo stopped
# measuring every step, favoured the name order: 23.2 against 23.7 min).
{ ls "$scenes" | sed -n 's/^\(run-.*-md\)\.json$/\1/p'
  ls "$scenes" | sed -n 's/^\(run-.*\)\.json$/\1/p' | grep -v -- '-md$'; } |
  xargs -P "$jobs" -I{} bash -c 'run_one {}' || failed=1
[ "$failed" = 0 ] && echo "study complete: results in out/paper/" || echo "study finished with failures (see out/paper/*.log)"
# (The lists above pick up the optional Mindlin–Deresiewicz runs run-*-md.json of issue 9
# when their scene files exist; the report then adds its contact-law section.)

# The report: README.md + fig-*.png in docs/paper-report/ (Qt Charts offscreen: no display, no VTK).
# A core-only build (FL_BUILD_GUI=OFF) has no report target; the GUI (Qt) is then switched on for it.
build="${FL_BUILD_DIR:-$root/build}"
log="$root/out/paper/report-build.log"
if ! cmake --build "$build" --target fabriclab-report -j "$jobs" > "$log" 2>&1; then
  { cmake -S "$root" -B "$build" -DFL_BUILD_GUI=ON && cmake --build "$build" --target fabriclab-report -j "$jobs"; } \
    >> "$log" 2>&1 || { echo "report: cannot build fabriclab-report (needs Qt6 Charts; see $log)"; exit 1; }
fi
cd "$root"  # --notes defaults to docs/paper-report-notes.md, relative to the working folder
"$build/app/fabriclab-report" --study out/paper --out docs/paper-report
echo "report: docs/paper-report/README.md"
exit "$failed"
