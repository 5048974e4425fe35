#!/usr/bin/env bash
# Installs the Debian 12 packages qsgi builds and tests with. Idempotent and non-interactive:
# packages already installed are skipped; runs apt-get directly as root, through sudo otherwise.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config python3
  libembree-dev
  libopenimageio-dev libopencv-core-dev openimageio-tools
  libopenexr-dev
  libtinygltf-dev libstb-dev
  libflann-dev liblz4-dev
  libtbb-dev
  nlohmann-json3-dev
  libcli11-dev
  libgtest-dev libgmock-dev
  libbenchmark-dev
  clang libclang-rt-14-dev    # libFuzzer (scripts/fuzz.sh)
  python3-numpy python3-matplotlib   # scripts/sweep.py: error figures and plots
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
