#!/usr/bin/env bash
# Installs every build, test and runtime dependency from Debian's packages.
# The one place the package list lives: README, .ci/run and docker/Dockerfile all call this script.
#   scripts/setup.sh            build + test dependencies (developers, CI)
#   scripts/setup.sh --runtime  only the shared libraries the binaries need (the Docker runtime stage)
set -euo pipefail

BUILD_PACKAGES=(
  build-essential cmake pkg-config git
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread nlohmann-json3-dev libhdf5-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev
  libcpp-httplib-dev
  python3 python3-h5py python3-numpy python3-jsonschema python3-matplotlib
  iproute2  # ss: tests/server/test_connections.py reads the listen backlog
  gmsh libgmsh-dev  # meshing api/examples/*.geo (scripts/make_gmsh_examples.sh); the MSH reader's cross-check
)
RUNTIME_PACKAGES=(
  libcholmod3 libopenblas0-pthread libhdf5-103-1 libcpp-httplib0.11 ca-certificates curl python3
)

if [[ "${1:-}" == "--runtime" ]]; then
  wanted=("${RUNTIME_PACKAGES[@]}")
else
  wanted=("${BUILD_PACKAGES[@]}")
fi

missing=()
for pkg in "${wanted[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#wanted[@]} packages already installed"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
