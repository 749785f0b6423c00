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
# The binding's Rust crate: its unit tests (WKB, GeoArrow buffers) linked to the venv's Python,
# unoptimised, crate and dependencies alike: they run in milliseconds, and compiling the core
# at opt-level 1 (and its dependencies at 2) for them took 70-80 s of a fresh clone's test run
# (unoptimised: under 50 s). Its lints run in CI (.ci/run, after the tests).
export PYO3_PYTHON="$PWD/$venv/bin/python"
cargo test -p skeletonise-python --config profile.test.opt-level=0 \
  --config 'profile.test.package."*".opt-level=0' --config 'profile.dev.package."*".opt-level=0'
if [ -z "${SKELETONISE_BIN:-}" ] && [ ! -x target/release/skeletonise ] && [ ! -x target/debug/skeletonise ]; then
  cargo build --bin skeletonise
fi
cd python/tests
exec "../../$venv/bin/python" -m pytest -q -p no:cacheprovider "$@"
