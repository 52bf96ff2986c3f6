#!/usr/bin/env bash
# Installs the Debian 12 packages hprt builds and runs with, only when missing.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git
  libembree-dev libtbb-dev libopenimageio-dev openimageio-tools
  libtinyobjloader-dev libgtest-dev nlohmann-json3-dev libcli11-dev
  libbenchmark-dev zlib1g-dev assimp-testmodels gnuplot-nox
  clang libclang-rt-14-dev clang-format
  slurm-wlm munge
  python3-dev pybind11-dev python3-numpy python3-pytest
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "setup: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
