#!/usr/bin/env bash
# Set up (if needed) and run the whole test suite. GL views need an X server: the tests run
# under Xvfb (xvfb-run) when there is no display. Extra arguments go to pytest.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$repo/packaging/setup.sh"
cd "$repo"
workers="$(nproc 2>/dev/null || echo 2)"
cmd=(.venv/bin/python -m pytest -n "$workers" "$@")
if [ -z "${DISPLAY:-}" ] && command -v xvfb-run >/dev/null 2>&1; then
  exec xvfb-run -a -s "-screen 0 1920x1080x24" "${cmd[@]}"
fi
exec "${cmd[@]}"
