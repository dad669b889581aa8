#!/usr/bin/env bash
# Runs the paper's whole study at full size: both specimens, the four consolidation histories and the
# eight cyclic runs of Table 2, as many at a time as there are cores (one thread each), reusing whatever
# is already prepared in out/paper/ (a step whose stages.json lists all its stages is skipped).
# Usage: scripts/paper-study.sh [JOBS]       (expect hours on a 2-core machine; see docs/performance.md)
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
run_one() {
  local name="$1"
  if done_already "$name"; then echo "== $name: already done"; return 0; fi
  echo "== $name: running"
  "$bin" "$scenes/$name.json" --threads 1 --overwrite --quiet > "$root/out/paper/$name.log" 2>&1 \
    && echo "== $name: done" || { echo "== $name: FAILED (see out/paper/$name.log)"; return 1; }
}
export -f run_one done_already
export root bin scenes
mkdir -p "$root/out/paper"

run_one specimen-isotropic
printf '%s\n' specimen-anisotropic history-isotropic-isotropic history-isotropic-k0 history-isotropic-ocr |
  xargs -P "$jobs" -I{} bash -c 'run_one {}'
run_one history-anisotropic-isotropic
ls "$scenes" | sed -n 's/^\(run-.*\)\.json$/\1/p' | xargs -P "$jobs" -I{} bash -c 'run_one {}'
echo "study complete: results in out/paper/"
