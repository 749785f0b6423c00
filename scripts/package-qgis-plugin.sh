#!/usr/bin/env bash
# Packs the QGIS plugin for QGIS's "Plugins › Manage and Install Plugins… › Install from ZIP":
# target/dist/skeletonise_qgis-VERSION.zip holds the folder skeletonise_qgis/ (the files of
# qgis/skeletonise_qgis, without __pycache__ and *.pyc), VERSION being the version= of its
# metadata.txt. The plugin needs the `skeletonise` wheel in QGIS's Python (its
# requirements.txt), so the manylinux wheel of target/wheels (abi3, manylinux_2_28 or older)
# is copied beside the ZIP; scripts/build-wheel.sh builds it first when target/wheels has
# none (a wheel already there is taken as it is: run scripts/build-wheel.sh to refresh it).
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
# A manylinux_2_X wheel (X ≤ 28) of target/wheels, or nothing.
manylinux_wheel() {
  local w minor found=
  for w in target/wheels/skeletonise-*-cp39-abi3-manylinux_2_*.whl; do
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
    echo "package-qgis-plugin.sh: scripts/build-wheel.sh left no manylinux_2_28 wheel in target/wheels" >&2
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
# python3's zipfile (always there, unlike `zip`): the folder and its files, sorted.
out=$PWD/$zip
(cd "$stage" && python3 -m zipfile -c "$out" skeletonise_qgis/)
cp "$wheel" "$dist/"
python3 -m zipfile -l "$zip"
echo "$zip"
echo "$dist/$(basename "$wheel")"
