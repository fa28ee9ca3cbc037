#!/usr/bin/env bash
# Install CoSTAR Instructor on the cell's PC: the one command.
#
#   bash packaging/install.sh              install, or upgrade when run again
#   bash packaging/install.sh --uninstall  remove everything it installed
#
# What goes where (a user install; as root the same goes system-wide):
#   the application    an isolated virtual environment:
#                      ${XDG_DATA_HOME:-~/.local/share}/costar-instructor/venv  (root: /opt/costar-instructor/venv)
#   costar, costar-instructor
#                      links in ~/.local/bin                                    (root: /usr/local/bin)
#   the menu entry     ${XDG_DATA_HOME:-~/.local/share}/applications/costar-instructor.desktop
#                                                                               (root: /usr/local/share/applications)
#   its icon           .../icons/hicolor/scalable/apps/costar-instructor.svg beside the menu entry
# and, with apt, the system libraries Qt and OpenGL need (system_packages.sh; sudo when not root).
#
# Options:
#   --user                 a user install even when run as root
#   --from PATH            install this wheel or source folder (default: this repository)
#   --pip-args "ARGS"      extra arguments for pip (e.g. "--no-index --find-links DIR" offline)
#   --no-system-packages   do not install system libraries with apt
#   --dry-run              say what would be done, change nothing
#   --uninstall            remove the environment, the links, the menu entry and the icon
# Environment: PYTHON, the Python 3.11+ to make the environment with (default python3).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
tag=install
app=costar-instructor
commands=(costar costar-instructor)

user_mode=0
source_path="$repo"
pip_args=()
system_packages=1
dry=0
uninstall=0
while (($#)); do
  case "$1" in
    --user) user_mode=1 ;;
    --from) source_path="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift ;;
    --pip-args) read -r -a pip_args <<<"$2"; shift ;;
    --no-system-packages) system_packages=0 ;;
    --dry-run) dry=1 ;;
    --uninstall) uninstall=1 ;;
    -h | --help) sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "$tag: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
  shift
done

if [ "$(id -u)" -eq 0 ] && [ "$user_mode" = 0 ]; then
  home_dir="/opt/$app"
  bin_dir=/usr/local/bin
  data_dir=/usr/local/share
else
  data_dir="${XDG_DATA_HOME:-$HOME/.local/share}"
  home_dir="$data_dir/$app"
  bin_dir="$HOME/.local/bin"
fi
venv="$home_dir/venv"
desktop_file="$data_dir/applications/$app.desktop"
icon_file="$data_dir/icons/hicolor/scalable/apps/$app.svg"

# run COMMAND...: run it, or under --dry-run print it.
run() {
  if [ "$dry" = 1 ]; then echo "+ $*"; else "$@"; fi
}

# ours LINK: true when LINK is a link into our environment (we may replace or remove it).
ours() {
  [ -L "$1" ] && case "$(readlink "$1")" in "$venv"/*) true ;; *) false ;; esac
}

do_uninstall() {
  local name
  for name in "${commands[@]}"; do
    if ours "$bin_dir/$name"; then run rm -f "$bin_dir/$name"; fi
  done
  [ -e "$desktop_file" ] && run rm -f "$desktop_file"
  [ -e "$icon_file" ] && run rm -f "$icon_file"
  [ -d "$home_dir" ] && run rm -rf "$home_dir"
  echo "$tag: removed CoSTAR Instructor ($home_dir, the links in $bin_dir, the menu entry)"
}

make_environment() {
  local python_bin="${PYTHON:-python3}"
  if ! "$python_bin" -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
    echo "$tag: Python 3.11 or newer is needed ($python_bin is $("$python_bin" -V 2>&1))" >&2
    exit 1
  fi
  if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c '' 2>/dev/null; then
    echo "$tag: making the environment $venv"
    run rm -rf "$venv"
    run mkdir -p "$home_dir"
    run "$python_bin" -m venv "$venv"
  fi
  echo "$tag: installing $source_path into $venv"
  run "$venv/bin/python" -m pip install -q --disable-pip-version-check "${pip_args[@]}" \
    "$source_path"
  # The same version number again (a development build) counts as installed for pip: put this
  # build in place anyway, without touching the dependencies.
  run "$venv/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall \
    --no-deps "${pip_args[@]}" "$source_path"
}

link_commands() {
  local name
  run mkdir -p "$bin_dir"
  for name in "${commands[@]}"; do
    if [ -e "$bin_dir/$name" ] && ! ours "$bin_dir/$name"; then
      echo "$tag: $bin_dir/$name exists and is not ours; leaving it (remove it and run again)" >&2
      continue
    fi
    run ln -sfn "$venv/bin/$name" "$bin_dir/$name"
  done
  case ":$PATH:" in
    *":$bin_dir:"*) ;;
    *) echo "$tag: add $bin_dir to your PATH to type costar and costar-instructor" ;;
  esac
}

add_menu_entry() {
  # The icon is the one the installed application ships (its package data).
  local shipped
  if [ "$dry" = 1 ]; then shipped="(the installed package's icons/$app.svg)"; else
    shipped="$("$venv/bin/python" -c 'import resources; print(resources.resource_path("icons", "costar-instructor.svg"))')"
  fi
  run mkdir -p "$(dirname "$icon_file")" "$(dirname "$desktop_file")"
  run cp "$shipped" "$icon_file"
  if [ "$dry" = 1 ]; then echo "+ write $desktop_file"; else
    sed -e "s|@BIN@|$bin_dir|g" -e "s|@ICON@|$icon_file|g" \
      "$repo/packaging/$app.desktop.in" >"$desktop_file.tmp"
    mv "$desktop_file.tmp" "$desktop_file"
  fi
  if command -v update-desktop-database >/dev/null 2>&1; then
    run update-desktop-database -q "$(dirname "$desktop_file")" || true
  fi
}

if [ "$uninstall" = 1 ]; then
  do_uninstall
  exit 0
fi
if [ "$system_packages" = 1 ]; then
  source "$repo/packaging/system_packages.sh"
  install_system_packages "$tag" "$dry"
fi
make_environment
link_commands
add_menu_entry
echo "$tag: done. costar doctor checks this computer; costar-instructor (or the menu) opens the Instructor"
