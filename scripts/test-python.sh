#!/usr/bin/env bash
# Builds the Python package (an abi3 wheel, maturin) and runs its tests (pytest) in a
# virtual environment under target/ (scripts/python-env.sh), so that nothing is installed
# system-wide. The tests compare with the command line's output: they use
# $SKELETONISE_BIN, else target/release/skeletonise, else target/debug/skeletonise
# (built here when neither exists).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/python-env.sh
venv=target/py-venv
# The binding's Rust crate: lints, and its unit tests (WKB, GeoArrow buffers) linked to the venv's Python.
export PYO3_PYTHON="$PWD/$venv/bin/python"
cargo clippy -p skeletonise-python --all-targets --quiet -- -D warnings
cargo test -p skeletonise-python
if [ -z "${SKELETONISE_BIN:-}" ] && [ ! -x target/release/skeletonise ] && [ ! -x target/debug/skeletonise ]; then
  cargo build --bin skeletonise
fi
cd python/tests
exec "../../$venv/bin/python" -m pytest -q -p no:cacheprovider "$@"
