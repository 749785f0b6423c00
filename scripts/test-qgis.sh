#!/usr/bin/env bash
# The QGIS plugin's tests in a real, headless QGIS (Debian's 3.22: installed when missing):
# every algorithm through processing.run (PyQGIS) and through qgis_process, compared with
# the command line's output (qgis/tests/test_provider.py, stdlib unittest in QGIS's own
# Python), and the plugin's ZIP (scripts/package-qgis-plugin.sh, with that wheel bundled) installed
# alone into a fresh profile and run by qgis_process. Uses the wheel of target/wheels
# (scripts/python-env.sh builds it) and the binary $SKELETONISE_BIN, else
# target/release/skeletonise, else target/debug/skeletonise.
set -euo pipefail
cd "$(dirname "$0")/.."
exec scripts/qgis-process.sh --python qgis/tests/test_provider.py "$@"
