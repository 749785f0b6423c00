#!/usr/bin/env bash
# Sets up a fresh Debian/Ubuntu machine (with Rust) and runs the demo pipeline on the
# embedded data: writes out/demo.gpkg.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
mkdir -p out
cargo run --release --quiet -- run pipelines/demo.yaml "$@"
ogrinfo -so -q out/demo.gpkg
