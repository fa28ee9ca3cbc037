# The system libraries CoSTAR Instructor needs on Debian/Ubuntu (Qt's xcb platform, OpenGL,
# Open3D, the virtual screen Xvfb), and a function that installs the missing ones with apt.
# Sourced by setup.sh (a development checkout) and install.sh (the cell PC); not run alone.

costar_apt_packages=(
  libusb-1.0-0 libgl1 libegl1 libgl1-mesa-dri libglx-mesa0 libxkbcommon0 libxkbcommon-x11-0
  libfontconfig1 libdbus-1-3 xvfb xauth libxcb-cursor0 libxcb-icccm4 libxcb-keysyms1
  libxcb-shape0 libxcb-xinerama0 libxcb-randr0 libxcb-render-util0 libxcb-image0
  libxcb-xfixes0 libxcb-xkb1
  # NodeGraphQt imports Qt.py, which loads QtMultimedia (it needs PulseAudio's client library).
  libpulse0
)

# install_system_packages TAG [DRY_RUN]: apt-get install the packages that are missing (with
# sudo when not root). TAG prefixes the messages; DRY_RUN=1 only says what it would install.
install_system_packages() {
  local tag="$1" dry="${2:-0}" pkg
  if ! command -v dpkg >/dev/null 2>&1; then
    echo "$tag: not a Debian/Ubuntu system; install the equivalents of: ${costar_apt_packages[*]}"
    return 0
  fi
  local missing=()
  for pkg in "${costar_apt_packages[@]}"; do
    dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
  done
  ((${#missing[@]})) || return 0
  echo "$tag: installing system packages: ${missing[*]}"
  [ "$dry" = 1 ] && return 0
  local sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo_cmd=(sudo); else
      echo "$tag: please install as root: apt-get install ${missing[*]}" >&2
      return 1
    fi
  fi
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive \
    apt-get install -y -q --no-install-recommends "${missing[@]}"
}
