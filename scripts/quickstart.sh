#!/usr/bin/env bash
# The whole product in one command, from a fresh clone on a fresh Debian 12 machine (as root or with sudo):
#   1. installs what is missing (scripts/setup.sh --quickstart: the build tools and libraries, the client's
#      Python packages, curl);
#   2. builds the command-line solver and the server only (the tests are built by scripts/test.sh);
#   3. starts contactd on a free loopback port, its job store in out/contactd-data;
#   4. submits the paper's example (api/examples/seed_layers.json) with the Python client, which streams its
#      progress and downloads the HDF5 result and its XDMF sidecar: out/seed_layers.hdf, out/seed_layers.xmf;
#   5. plots it (out/seed_layers.png: the pressure per iteration, the deformed mesh by von Mises stress);
#   6. stops the server.
# --no-build: use the build directory as it is and install nothing (the README test runs it so).
# BUILD_DIR (default build) and OUT_DIR (default out) choose the directories.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
OUT_DIR=${OUT_DIR:-out}
case "${1:-}" in
  "") build=1 ;;
  --no-build) build=0 ;;
  *)
    echo "usage: $0 [--no-build]" >&2
    exit 2
    ;;
esac

if ((build)); then
  bash scripts/setup.sh --quickstart
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCONTACT_BUILD_TESTS=OFF -DCONTACT_BUILD_BENCH=OFF > /dev/null
  cmake --build "$BUILD_DIR" -j "$(nproc)" --target contact-solve contactd
fi

mkdir -p "$OUT_DIR"
log="$OUT_DIR/contactd.log"
# Created here: the background server's redirection opens it in the forked child, which may not have run yet when
# the loop below first reads it.
: > "$log"
# A server of its own: no token, whatever the environment says (the client would not know it).
env -u CONTACTD_TOKEN "$BUILD_DIR/server/contactd" --host 127.0.0.1 --port 0 --data-dir "$OUT_DIR/contactd-data" \
  > "$log" 2>&1 &
server=$!
trap 'kill "$server" 2> /dev/null || true' EXIT

url=""
for _ in $(seq 1 200); do
  url=$(sed -n 's/^contactd .* listening on \(http:[^ ]*\) .*/\1/p' "$log")
  [[ -n "$url" ]] && break
  if ! kill -0 "$server" 2> /dev/null; then
    echo "quickstart: contactd exited:" >&2
    cat "$log" >&2
    exit 1
  fi
  sleep 0.05
done
if [[ -z "$url" ]]; then
  echo "quickstart: contactd did not start within 10 s:" >&2
  cat "$log" >&2
  exit 1
fi
echo "quickstart: contactd serves $url (its log: $log); open $url/ in a browser to watch its jobs"

export CONTACT_URL=$url
unset CONTACT_TOKEN
echo "quickstart: submitting api/examples/seed_layers.json (the paper's scheme) and following it"
clients/contact_client.py submit api/examples/seed_layers.json --wait \
  -o "$OUT_DIR/seed_layers.hdf" --xmf --events-out "$OUT_DIR/seed_layers-events.ndjson"
clients/contact_client.py plot "$OUT_DIR/seed_layers.hdf" -o "$OUT_DIR/seed_layers.png" \
  --events "$OUT_DIR/seed_layers-events.ndjson"

kill -TERM "$server"
wait "$server"  # contactd stops gracefully and exits 0
trap - EXIT
xmf="$OUT_DIR/seed_layers.xmf"
[[ "$xmf" == /* ]] || xmf="./$xmf"  # ParaView's XDMF reader needs a path, not a bare name
echo "quickstart: stopped contactd. Results: $OUT_DIR/seed_layers.hdf (h5py; in ParaView open $xmf)" \
  "and the figure $OUT_DIR/seed_layers.png"
