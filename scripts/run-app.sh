#!/usr/bin/env bash
# The README's first command: install dependencies, build, and start FabricLab on the default scene.
# With no display (ssh, CI) it runs the same scene headless instead and says so.
# Extra arguments are passed to the program (e.g. another scene file).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
build="${FL_BUILD_DIR:-$root/build}"
scene="$root/resources/scenes/default.json"
if [ $# -gt 0 ]; then scene="$1"; shift; fi
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
  echo "run-app: no display found; running the scene headless (fabriclab --headless)"
  exec "$build/app/fabriclab" --headless "$scene" "$@"
fi
exec "$build/app/fabriclab" "$scene" "$@"
