#!/usr/bin/env bash
# Runs Debian's `qgis_process` with this checkout's QGIS plugin (qgis/skeletonise_qgis) and
# the skeletonise wheel available, in a throw-away QGIS profile (the user's own is never
# touched), e.g.
#   scripts/qgis-process.sh run skeletonise:skeletonise \
#     --INPUT='tests/data/gshhg-train.gpkg|layername=lakes_scotland' --OUTPUT=out/q.gpkg
# On a fresh Debian/Ubuntu machine it first installs `qgis` and `python3-qgis`, and builds
# the wheel (scripts/python-env.sh) when target/wheels has none. The wheel is unpacked
# into target/qgis-python, QGIS's Python's path for it: nothing else is installed there
# (QGIS's numpy is the wheel's only need; pandas and shapely are not).
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
site=target/qgis-python
if [ ! -f "$site/.wheel" ] || [ "$(cat "$site/.wheel")" != "$(stat -c '%n %Y %s' "$wheel")" ]; then
  rm -rf "$site"
  mkdir -p "$site"
  /usr/bin/python3 -m zipfile -e "$wheel" "$site"
  stat -c '%n %Y %s' "$wheel" >"$site/.wheel"
fi
profile=$(mktemp -d "${TMPDIR:-/tmp}/skeletonise-qgis-profile.XXXXXX")
trap 'rm -rf "$profile"' EXIT
export QGIS_CUSTOM_CONFIG_PATH=$profile
export QGIS_PLUGINPATH=$root/qgis${QGIS_PLUGINPATH:+:$QGIS_PLUGINPATH}
export PYTHONPATH=$root/$site${PYTHONPATH:+:$PYTHONPATH}
export QT_QPA_PLATFORM=${QT_QPA_PLATFORM:-offscreen}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$profile}
# Debian's /usr/bin/qgis_process wrapper passes --noversioncheck from /etc/default/qgis,
# which qgis_process does not know: call the program itself where it is there.
qp=qgis_process
command -v qgis_process.bin >/dev/null 2>&1 && qp=qgis_process.bin
if [ "${1:-}" = "--python" ]; then
  shift
  "$qp" plugins enable skeletonise_qgis >/dev/null
  exec /usr/bin/python3 "$@"
fi
"$qp" plugins enable skeletonise_qgis >/dev/null
exec "$qp" "$@"
