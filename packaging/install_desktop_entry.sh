#!/usr/bin/env bash
# Install a desktop entry for the cell PC's user: CoSTAR Instructor in the application menu,
# opening *.costar.json plans. Runs setup first. Usage: bash packaging/install_desktop_entry.sh
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$repo/packaging/setup.sh"
apps="${XDG_DATA_HOME:-$HOME/.local/share}/applications"
mkdir -p "$apps"
sed "s|@REPO@|$repo|g" "$repo/packaging/costar-instructor.desktop.in" > "$apps/costar-instructor.desktop"
echo "installed $apps/costar-instructor.desktop"
