#!/usr/bin/env bash
# Installs the Debian 12 packages tactus builds with; does nothing when all are present.
# Usage: tools/install-deps.sh [core|all]   (default: all)
set -euo pipefail

core=(build-essential cmake pkg-config git
      libjansson-dev libcmocka-dev
      clang libclang-rt-14-dev)        # clang: libFuzzer target of the scenario loader
optional=(libbullet-dev libode-dev libassimp-dev liburdfdom-dev libtinyxml-dev
          libosmesa6-dev libglfw3-dev libpng-dev
          libplplot-dev plplot-driver-cairo
          xvfb xauth                   # Xvfb: the window tests; xvfb-run for benches by hand
          cyclonedds-dev cyclonedds-tools  # sessions over several processes (docs/distributed.md); idlc
          tetgen
          libimgui-dev xdotool         # the window's panels (Dear ImGui); synthetic input in its test
          python3                      # the network and window tests read their CSVs with it; the instruments hands' generator
          libgts-dev libnifti2-dev)      # the LAGB asset pipeline: marching cubes, a user's NIfTI volume

want=("${core[@]}")
[ "${1:-all}" = core ] || want+=("${optional[@]}")

missing=()
for p in "${want[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
