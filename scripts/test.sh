#!/usr/bin/env bash
# Sets up a fresh Debian/Ubuntu machine (with Rust) and runs every test: unit tests,
# end-to-end tests through the real binary on real GeoPackage files, doc tests.
# The training data is expected at ../shared/data (beside the repository).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
cargo test --all-targets "$@"
cargo test --doc
