#!/usr/bin/env bash
# Sets up a fresh Debian/Ubuntu machine (with Rust) and runs every test: unit tests,
# end-to-end tests through the real binary on real GeoPackage files, doc tests, and the
# core's tests once more without GDAL (`--no-default-features`).
# The test data lives in tests/data (GSHHG, Wessel & Smith), so a fresh clone needs nothing beside it.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/test-deps.sh
# Installed above: the PostGIS test must run, not skip.
export SKELETONISE_REQUIRE_POSTGIS=1
cargo test --all-targets "$@"
cargo test --doc
# The core without GDAL, as the Python binding builds it (the GDAL-only targets are skipped).
cargo test --no-default-features --all-targets "$@"
