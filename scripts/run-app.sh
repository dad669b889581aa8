#!/usr/bin/env bash
# The README's first command: install dependencies, build, and start FabricLab on the default scene.
# Extra arguments are passed to the program.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
build="${FL_BUILD_DIR:-$root/build}"
exec "$build/app/fabriclab-run" "$@"
