#!/usr/bin/env bash
# Installs the Debian 12 packages qsgi needs, in two sets, so a first run waits only for what it uses:
#   scripts/setup.sh          building and rendering (scripts/run.sh): compiler, CMake and the libraries
#   scripts/setup.sh --test   the above, and what the test command adds: GoogleTest and Google Benchmark,
#                             clang with libFuzzer (scripts/fuzz.sh), oiiotool, numpy and matplotlib
#                             (scripts/sweep.py, reference checks), the npm packages of scripts/gltf-check
#                             and, in a venv of the project's own (venv/ in scripts/usd-check), the pinned
#                             OpenUSD of scripts/usd-check/requirements.txt that checks --usd-out
# Idempotent and non-interactive: packages already installed are skipped; runs apt-get directly as
# root, through sudo otherwise. Slurm is installed by scripts/test-slurm.sh, which alone uses it.
set -euo pipefail

run_packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev
  libopenimageio-dev        # found through its pkg-config file (CMakeLists.txt says why)
  libopenexr-dev
  libpng-dev                # PNG textures (lib/scene/texture_colour.cpp)
  libtinygltf-dev libstb-dev
  libflann-dev liblz4-dev
  libxxhash-dev             # checksums of the frame files (timing.json, --resume)
  libtbb-dev
  nlohmann-json3-dev
  libcli11-dev
  libeigen3-dev             # the least-squares vertex fit's sparse factorisation (lib/estimate/vertex_fit.cpp)
)
test_packages=(
  python3 python3-numpy python3-matplotlib   # scripts/sweep.py, tests/data/make_inputs.py, reference checks
  python3-xxhash            # the Slurm merge verifies chunk files (scripts/qsgibatch/output_folder.py)
  openimageio-tools
  strace                    # tests/read_once_test.cpp counts the opens of each input
  libgtest-dev libgmock-dev
  libbenchmark-dev
  clang libclang-rt-14-dev    # libFuzzer (scripts/fuzz.sh)
  python3-venv              # the venv of scripts/usd-check: Debian's python3 is externally managed (PEP 668)
)

case "${1:-}" in
  "") packages=("${run_packages[@]}"); with_tests=0 ;;
  --test) packages=("${run_packages[@]}" "${test_packages[@]}"); with_tests=1 ;;
  *) echo "usage: scripts/setup.sh [--test]" >&2; exit 2 ;;
esac

if [ "$with_tests" = 1 ]; then
  # scripts/gltf-check (the Khronos glTF-Validator for --gltf-out) needs node and npm: Debian's
  # nodejs and npm where the machine has none (a machine with NodeSource's nodejs has both, and
  # Debian's npm would conflict with it).
  command -v node >/dev/null 2>&1 || packages+=(nodejs)
  command -v npm >/dev/null 2>&1 || packages+=(npm)
fi

# The glTF checkers (npm packages pinned by scripts/gltf-check/package-lock.json), after the
# Debian packages; skipped when already installed at the locked versions.
install_gltf_checkers() {
  [ "$with_tests" = 1 ] || return 0
  local dir
  dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/gltf-check"
  if node -e 'const l = require(process.argv[1] + "/package-lock.json").packages;
              for (const [p, v] of Object.entries(l)) if (p && require(process.argv[1] + "/" + p + "/package.json").version !== v.version) process.exit(1);' \
       "$dir" 2>/dev/null; then
    return 0
  fi
  echo "setup: npm ci in $dir"
  (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
}

# OpenUSD's Python package (usd-core, pinned by scripts/usd-check/requirements.txt) for the checker
# of --usd-out (scripts/usd-check/check_usd.py), after the Debian packages, in a venv of the
# project's own made with Debian's python3: its numpy comes from python3-numpy
# (--system-site-packages), usd-core from PyPI. Skipped when the venv already has the pinned version.
install_usd_checker() {
  [ "$with_tests" = 1 ] || return 0
  local dir venv pin
  dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/usd-check"
  venv="$dir/venv"
  pin="$(sed -n 's/^usd-core==\([^[:space:]#]*\).*/\1/p' "$dir/requirements.txt")"
  if [ -x "$venv/bin/python" ] &&
     [ "$("$venv/bin/python" -c 'import importlib.metadata as m; print(m.version("usd-core"))' 2>/dev/null)" = "$pin" ]; then
    return 0
  fi
  echo "setup: usd-core==$pin into $venv"
  # A venv whose interpreter no longer runs (Debian's python3 upgraded or removed) is made anew.
  "$venv/bin/python" -c '' 2>/dev/null || /usr/bin/python3 -m venv --clear --system-site-packages "$venv"
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-input --only-binary=:all: \
    -r "$dir/requirements.txt"
}

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  install_gltf_checkers
  install_usd_checker
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
install_gltf_checkers
install_usd_checker
