#!/usr/bin/env bash
# The README's test command: install dependencies, build, run every test (GUI tests under Xvfb).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
cd "${FL_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j "$(nproc)"
