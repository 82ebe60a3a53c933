#!/usr/bin/env bash
# Install the Debian 12 packages gaitsim needs (idempotent, non-interactive), then configure and
# build into build/. Run as root on a fresh machine, or as a user with sudo.
#   scripts/setup.sh              install packages if missing, build
#   scripts/setup.sh --deps-only  install packages only
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake pkg-config clang
  libmujoco-dev libmujoco-samples libqhull-dev
  coinor-libipopt-dev libopenblas-dev
  libosmesa6-dev libgl-dev libpng-dev libcjson-dev
  ffmpeg
  xvfb x11-apps xdotool
  python3 python3-numpy python3-scipy python3-matplotlib
  munge slurm-wlm
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install packages" >&2; exit 1; }
    SUDO=sudo
  fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
[ "${1:-}" = "--deps-only" ] && exit 0

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
echo "setup: built build/gaitsim"
