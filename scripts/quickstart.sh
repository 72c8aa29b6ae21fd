#!/usr/bin/env bash
# Installs what is missing, builds, and solves the paper's example (api/examples/seed_layers.json):
# prints one progress line per DDM iteration and a summary, and writes out/seed_layers.hdf (+ .xmf sidecar).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build -j "$(nproc)"
mkdir -p out
./build/contact-solve api/examples/seed_layers.json -o out/seed_layers.hdf
