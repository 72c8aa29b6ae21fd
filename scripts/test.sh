#!/usr/bin/env bash
# Installs what is missing, builds everything (Release: the solver, the server, the tests and the benchmarks)
# and runs the whole test suite with CTest. This is the README's test command; .ci/run calls it.
# (The tests and benchmarks are switched on explicitly: scripts/quickstart.sh configures the same build
# directory without them.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCONTACT_BUILD_TESTS=ON -DCONTACT_BUILD_BENCH=ON
cmake --build build -j "$(nproc)"
cd build
ctest --output-on-failure -j "$(nproc)" --timeout 900
