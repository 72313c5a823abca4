#!/usr/bin/env bash
# Installs the Debian 12 packages papertear needs to build, test and benchmark. Installs only
# what is missing (checked with dpkg -s), so a second run is quick and needs no network.
# Works as root; otherwise uses sudo when it is available.
set -euo pipefail

# Every package the project needs, in one place. Add new ones here.
PACKAGES=(
  build-essential
  cmake
  ninja-build
  g++
  clang
  libeigen3-dev
  libtbb-dev
  libxsimd-dev
  libbenchmark-dev
  catch2
  libembree-dev
  libpng-dev
  libstb-dev
  libtomlplusplus-dev
  libcli11-dev
  libtinygltf-dev
  nlohmann-json3-dev
  gnuplot-nox            # sweep plots (papertear sweep); without it the sweep warns and skips them
  python3-dev            # the Python module (tools/python): headers,
  python3-pybind11       #   the bindings,
  python3-numpy          #   arrays (and Debian's Blender for glTF import: it does not pull it in),
  python3-pytest         #   and its tests
  ffmpeg                 # video.mp4 of every run; ffprobe checks it (client tests)
  nodejs                 # client tests and the viewer: glTF validator, three.js, playwright-core
  npm
  blender                # client test: imports the run's glTF (tools/blender/)
  chromium               # client test: the viewer in a headless browser
)

is_installed() {
  dpkg -s "$1" 2>/dev/null | grep -q '^Status: install ok installed$'
}

# Packages whose program may come from elsewhere: NodeSource's nodejs, say, carries its own
# npm and conflicts with Debian's. Skipped when the program is already on the PATH.
declare -A PROGRAM_OF=([npm]=npm)

missing=()
for pkg in "${PACKAGES[@]}"; do
  if [[ -n "${PROGRAM_OF[$pkg]:-}" ]] && command -v "${PROGRAM_OF[$pkg]}" >/dev/null 2>&1; then continue; fi
  is_installed "$pkg" || missing+=("$pkg")
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#PACKAGES[@]} packages are installed"
  exit 0
fi

if [[ $(id -u) -eq 0 ]]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "install-deps: missing packages: ${missing[*]}" >&2
  echo "install-deps: not root and sudo is not available; install them and run again" >&2
  exit 1
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update
"${as_root[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
