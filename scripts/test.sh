#!/usr/bin/env bash
# The README's test command: install dependencies, build, run every test (GUI tests under Xvfb), then the
# reliability pass (ASan+UBSan engine tests, TSan of the OpenMP core, a short fuzz pass).
# FL_RELIABILITY_SKIP="asan tsan fuzz" skips parts of the reliability pass for a quick local run.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
status=0
(cd "${FL_BUILD_DIR:-$root/build}" && ctest --output-on-failure -j "$(nproc)") 2>&1 | tee "$log" || status=1
reliability=""
"$root/scripts/ci-reliability.sh" || { status=1; reliability="; the reliability pass FAILED (see above)"; }
# One plain closing line with the main suite's counts (and the reliability pass's failure, which has no count).
total=$(sed -n 's/.*tests failed out of \([0-9]*\).*/\1/p' "$log" | tail -1)
failed=$(sed -n 's/.* \([0-9]*\) tests failed out of.*/\1/p' "$log" | tail -1)
[ -n "$total" ] && echo "tests: $((total - ${failed:-0})) passed, ${failed:-0} failed$reliability"
exit $status
