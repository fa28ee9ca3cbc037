#!/usr/bin/env bash
# Set up (if needed) and open the Instructor on the simulated cell. Extra arguments go to
# costar-instructor (e.g. a plan file).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$repo/packaging/setup.sh"
exec "$repo/.venv/bin/costar-instructor" "$@"
