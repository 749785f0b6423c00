#!/usr/bin/env bash
# Runs Debian's `qgis_process` with this checkout's QGIS plugin (qgis/skeletonise_qgis) and
# the skeletonise wheel available, in a throw-away QGIS profile (the user's own is never
# touched), e.g.
#   scripts/qgis-process.sh run skeletonise:skeletonise \
#     --INPUT='tests/data/gshhg-train.gpkg|layername=lakes_scotland' --OUTPUT=out/q.gpkg
# On a fresh Debian/Ubuntu machine it first installs `qgis` and `python3-qgis`, and builds
# the wheel (scripts/python-env.sh) when target/wheels has none. The wheel is unpacked
# into the profile's python folder, as the README's installation does: nothing else is
# installed (QGIS's numpy is the wheel's only need; pandas and shapely are not).
#   scripts/qgis-process.sh --python SCRIPT.py ARGS…   runs a PyQGIS script the same way
#                                                      (the plugin's tests: scripts/test-qgis.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
if ! command -v qgis_process >/dev/null 2>&1 || ! /usr/bin/python3 -c 'import qgis.core' 2>/dev/null; then
  scripts/apt-install.sh "for QGIS" qgis python3-qgis
fi
if ! ls target/wheels/skeletonise-*.whl >/dev/null 2>&1; then
  scripts/python-env.sh
fi
wheel=$(ls -t target/wheels/skeletonise-*.whl | head -n 1)
profile=$(mktemp -d "${TMPDIR:-/tmp}/skeletonise-qgis-profile.XXXXXX")
trap 'rm -rf "$profile"' EXIT
export QGIS_CUSTOM_CONFIG_PATH=$profile
export QGIS_PLUGINPATH=$root/qgis${QGIS_PLUGINPATH:+:$QGIS_PLUGINPATH}
# The wheel goes where the README tells users to put it: the profile's python folder, which
# QGIS puts on its Python's path (SKELETONISE_QGIS_NO_WHEEL=1 leaves it out, for the test of
# the provider without it).
mkdir -p "$profile/profiles/default/python"
if [ -z "${SKELETONISE_QGIS_NO_WHEEL:-}" ]; then
  /usr/bin/python3 -m zipfile -e "$wheel" "$profile/profiles/default/python"
fi
export QT_QPA_PLATFORM=${QT_QPA_PLATFORM:-offscreen}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$profile}
# Debian's /usr/bin/qgis_process wrapper passes --noversioncheck from /etc/default/qgis,
# which qgis_process does not know: call the program itself where it is there.
qp=qgis_process
command -v qgis_process.bin >/dev/null 2>&1 && qp=qgis_process.bin
if [ "${1:-}" = "--python" ]; then
  shift
  # A PyQGIS script outside QGIS does not read the profile's python folder itself.
  export PYTHONPATH=$profile/profiles/default/python${PYTHONPATH:+:$PYTHONPATH}
  /usr/bin/python3 "$@"
  exit
fi
"$qp" plugins enable skeletonise_qgis >/dev/null
"$qp" "$@"
