#!/usr/bin/env bash
# Sets up a fresh Debian/Ubuntu machine (with Rust) and runs every test: unit tests,
# end-to-end tests through the real binary on real GeoPackage files, doc tests (and the API
# documentation, built without a warning), the core checked without GDAL
# (`--no-default-features`), the Python package's tests (scripts/test-python.sh: the wheel,
# pytest, a two-worker Dask cluster on loopback) and the QGIS plugin's (scripts/test-qgis.sh:
# a real, headless QGIS 3.22).
# The test data lives in tests/data (GSHHG, Wessel & Smith), so a fresh clone needs nothing beside it.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each stage's own time, printed when it ends (where the ten minutes go).
mark=$SECONDS
took() { echo "test.sh: $1 took $((SECONDS - mark)) s"; mark=$SECONDS; }
scripts/deps.sh
scripts/test-deps.sh
took "set-up"
# Installed above: the PostGIS test must run, not skip.
export SKELETONISE_REQUIRE_POSTGIS=1
cargo test --all-targets "$@"
took "cargo test --all-targets"
cargo test --doc
took "doc tests"
# The API documentation builds without a warning (no link to a private or missing item).
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet
took "API documentation"
# The patched dependency's own unit tests (vendor/boostvoronoi/PATCHES.md), optimised a little:
# unoptimised they run 27 s, at opt-level 1 2 s for a few seconds more of compiling.
CARGO_PROFILE_TEST_OPT_LEVEL=1 CARGO_TARGET_DIR=$PWD/target/vendor \
  cargo test --quiet --manifest-path vendor/boostvoronoi/Cargo.toml --lib
took "vendored boostvoronoi"
# With SKELETONISE_FREE_DISK=1 (CI) a build nothing after it uses is removed (300 MB).
if [ "${SKELETONISE_FREE_DISK:-}" = 1 ]; then rm -rf target/vendor; fi
# The core without GDAL, as the Python binding builds it: every target compiles with the
# GDAL-only ones skipped. Its tests are those that ran above (nothing is compiled only without
# GDAL), and the binding's own tests below build and run the core without GDAL.
cargo check --quiet --no-default-features --all-targets
took "without GDAL"
# The Python package from its manylinux_2_28 wheel (scripts/build-wheel.sh: zig, checked by
# auditwheel), profile wheel-test: release's optimisation without its fat LTO (cold, 2 cores:
# 105 s against 134 s; the results are the same). target/zig shares nothing with the builds above.
SKELETONISE_WHEEL_PROFILE=${SKELETONISE_WHEEL_PROFILE:-wheel-test} scripts/test-python.sh
took "Python package"
# The wheel is in target/wheels; its build directory is not needed again (CI: 570 MB).
if [ "${SKELETONISE_FREE_DISK:-}" = 1 ]; then rm -rf target/zig; fi
# The QGIS plugin in Debian's QGIS (installed when missing), with that wheel.
scripts/test-qgis.sh
took "QGIS plugin"
