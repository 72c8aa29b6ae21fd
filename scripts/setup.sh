#!/usr/bin/env bash
# Installs what is missing from Debian's packages. The one place the package list lives: the README,
# scripts/quickstart.sh, scripts/test.sh, .ci/run and docker/Dockerfile all call this script.
#   scripts/setup.sh               everything: build, client and test dependencies (developers, CI)
#   scripts/setup.sh --build       only what compiling contact-solve and contactd needs (the Docker build stage)
#   scripts/setup.sh --quickstart  --build plus the Python client's packages and curl (scripts/quickstart.sh)
#   scripts/setup.sh --runtime     only the shared libraries the binaries need (the Docker runtime stage)
set -euo pipefail

BUILD_PACKAGES=(
  build-essential cmake pkg-config git
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread nlohmann-json3-dev libhdf5-dev libcli11-dev
  libcpp-httplib-dev
  libglpk-dev                 # the collapse analysis's rigid-block statics, a linear program (solver/limit/)
  libopenmpi-dev openmpi-bin  # bodies on MPI ranks (docs/parallel.md); the build works without them
)
# The Python client (clients/): HTTP with the standard library; results, plots and the progress bar.
CLIENT_PACKAGES=(
  python3 python3-h5py python3-numpy python3-matplotlib python3-tqdm curl
)
TEST_PACKAGES=(
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-jsonschema
  iproute2                                  # ss: tests/server/test_connections.py reads the listen backlog
  chromium chromium-driver python3-selenium # tests/clients/test_web_page.py drives the web page
  gmsh libgmsh-dev                          # scripts/make_gmsh_examples.sh; the MSH reader checked against libgmsh
  clang-format                              # tests/unit/test_format.py: the code as .clang-format says (Debian's 14)
)
RUNTIME_PACKAGES=(
  libcholmod3 libumfpack5 libopenblas0-pthread libhdf5-103-1 libcpp-httplib0.11 libglpk40 ca-certificates curl
  libopenmpi3 openmpi-bin     # mpirun, for contactd --mpi-launcher
)

case "${1:-}" in
  "") wanted=("${BUILD_PACKAGES[@]}" "${CLIENT_PACKAGES[@]}" "${TEST_PACKAGES[@]}") ;;
  --build) wanted=("${BUILD_PACKAGES[@]}") ;;
  --quickstart) wanted=("${BUILD_PACKAGES[@]}" "${CLIENT_PACKAGES[@]}") ;;
  --runtime) wanted=("${RUNTIME_PACKAGES[@]}") ;;
  *)
    echo "usage: $0 [--build | --quickstart | --runtime]" >&2
    exit 2
    ;;
esac

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
