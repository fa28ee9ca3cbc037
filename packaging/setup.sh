#!/usr/bin/env bash
# Set up CoSTAR Instructor on this machine: system libraries (apt) when missing, and a
# virtual environment at .venv in the repository root with the project installed in it.
# Idempotent: a second run only checks. Usage: bash packaging/setup.sh
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"

# System libraries (the list is in system_packages.sh, shared with install.sh).
source "$repo/packaging/system_packages.sh"
install_system_packages setup

python_bin="${PYTHON:-python3}"
if ! "$python_bin" -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
  echo "setup: Python 3.11 or newer is needed ($python_bin is $("$python_bin" -V 2>&1))" >&2
  exit 1
fi
if [ ! -x .venv/bin/python ]; then
  echo "setup: creating the virtual environment .venv"
  "$python_bin" -m venv .venv
fi
# Reinstall only when the dependencies changed (the stamp holds pyproject.toml's hash).
stamp=.venv/.costar-installed
want="$(sha256sum pyproject.toml | cut -d' ' -f1)"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "setup: installing the project and its dependencies into .venv"
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -e ".[dev]"
  echo "$want" > "$stamp"
fi
echo "setup: ready"
