#!/usr/bin/env bash
# Meshes every api/examples/*.geo with Gmsh (Debian's gmsh package, which scripts/setup.sh installs) into the .msh
# next to it, in the MSH 4.1 ASCII format the solver reads (docs/job-format.md, "Gmsh meshes"). The .msh files
# are committed with their .geo and the job that uses them: run this after changing a .geo, then the tests
# (ctest -R Gmsh), which check the jobs against exact solutions and formulas.
#   scripts/make_gmsh_examples.sh           every .geo
#   scripts/make_gmsh_examples.sh x.geo     the ones given (paths or names under api/examples/)
set -euo pipefail
cd "$(dirname "$0")/../api/examples"
command -v gmsh >/dev/null || { echo "make_gmsh_examples: gmsh is not installed (scripts/setup.sh installs it)" >&2; exit 1; }
if (($# == 0)); then set -- *.geo; fi
for geo in "$@"; do
  geo=$(basename "$geo")
  msh="${geo%.geo}.msh"
  gmsh -2 "$geo" -format msh41 -o "$msh" -v 2 >/dev/null
  echo "make_gmsh_examples: $geo -> $msh ($(gmsh --version 2>&1 | tail -1)): $(awk '/^\$Nodes/{getline; print $2; exit}' "$msh") nodes"
done
