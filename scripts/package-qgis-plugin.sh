#!/usr/bin/env bash
# Packs the QGIS plugin for QGIS's "Plugins › Manage and Install Plugins… › Install from ZIP":
# target/dist/skeletonise_qgis-VERSION.zip holds the folder skeletonise_qgis/ (the files of
# qgis/skeletonise_qgis, without __pycache__ and *.pyc), VERSION being the version= of its
# metadata.txt. The plugin needs the `skeletonise` wheel of the same version, so the ZIP
# carries it for x86-64 Linux: the manylinux wheel of target/wheels (abi3, manylinux_2_28
# or older) unpacked into skeletonise_qgis/_bundled/linux_x86_64/ (its `skeletonise`
# package and .dist-info as files: a native extension cannot be imported from inside a
# ZIP; the plugin's bundle.py puts the folder on sys.path where it runs), so that on Linux
# Install from ZIP is the only step. The wheel itself is copied beside the ZIP too, for
# those who install it into QGIS's Python themselves. scripts/build-wheel.sh builds it
# first when target/wheels has none of that version (a wheel already there is taken as it
# is: run scripts/build-wheel.sh to refresh it).
#   scripts/package-qgis-plugin.sh   # then lists the ZIP; the last two lines: ZIP and wheel paths
# Older files of the same names in target/dist are replaced.
set -euo pipefail
cd "$(dirname "$0")/.."
plugin=qgis/skeletonise_qgis
version=$(sed -n 's/^version[[:space:]]*=[[:space:]]*//p' "$plugin/metadata.txt" | tr -d '\r' | head -n 1)
if [ -z "$version" ]; then
  echo "package-qgis-plugin.sh: no version= in $plugin/metadata.txt" >&2
  exit 1
fi
# A manylinux_2_X wheel (X ≤ 28) of the plugin's version in target/wheels, or nothing.
manylinux_wheel() {
  local w minor found=
  for w in target/wheels/skeletonise-"$version"-cp39-abi3-manylinux_2_*_x86_64.whl; do
    [ -f "$w" ] || continue
    minor=$(basename "$w" | sed -n 's/.*-manylinux_2_\([0-9][0-9]*\)_.*/\1/p')
    if [ -n "$minor" ] && [ "$minor" -le 28 ]; then
      found=$w
    fi
  done
  printf '%s' "$found"
}
wheel=$(manylinux_wheel)
if [ -z "$wheel" ]; then
  scripts/build-wheel.sh
  wheel=$(manylinux_wheel)
  if [ -z "$wheel" ]; then
    echo "package-qgis-plugin.sh: scripts/build-wheel.sh left no manylinux_2_28 x86_64 wheel of version $version" \
      "(the plugin's metadata.txt) in target/wheels" >&2
    exit 1
  fi
fi
dist=target/dist
zip=$dist/skeletonise_qgis-$version.zip
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$dist"
rm -f "$dist"/skeletonise_qgis-*.zip "$dist"/skeletonise-*.whl
cp -R "$plugin" "$stage/skeletonise_qgis"
find "$stage" \( -name __pycache__ -o -name '*.pyc' \) -prune -exec rm -rf {} +
# The wheel's files, where the plugin's bundle.py looks for them (FOLDER there).
bundled=$stage/skeletonise_qgis/_bundled/linux_x86_64
rm -rf "$stage/skeletonise_qgis/_bundled"
mkdir -p "$bundled"
python3 -m zipfile -e "$wheel" "$bundled"
if [ ! -f "$bundled/skeletonise/__init__.py" ] || ! ls "$bundled"/skeletonise/_core*.so >/dev/null 2>&1; then
  echo "package-qgis-plugin.sh: $wheel has no skeletonise/__init__.py and _core*.so" >&2
  exit 1
fi
# python3's zipfile (always there, unlike `zip`): the folder and its files, sorted, deflated
# (`python3 -m zipfile -c` stores them: the extension alone is 30 MB, the plugin repository
# takes at most 25 MB).
out=$PWD/$zip
(cd "$stage" && python3 - "$out" <<'PY'
import os
import sys
import zipfile

with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED, compresslevel=9) as z:
    for folder, dirs, files in os.walk("skeletonise_qgis"):
        dirs.sort()
        z.write(folder)
        for name in sorted(files):
            z.write(os.path.join(folder, name))
PY
)
cp "$wheel" "$dist/"
python3 -m zipfile -l "$zip"
echo "$zip"
echo "$dist/$(basename "$wheel")"
