#!/usr/bin/env bash
# The README's picture of the report: the training lakes through pipelines/compare-methods.yaml
# (out/lakes.gpkg and its report out/lakes.html), opened in headless Chromium with the bars shown
# (report.html#bars) and saved as docs/img/report-lakes.png. Needs chromium (scripts/deps.sh --browser).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh --browser
mkdir -p out docs/img
cargo run --release --quiet -- run pipelines/compare-methods.yaml --set input.layer=lakes_scotland -o out/lakes.gpkg -q
browser=$(command -v chromium || command -v chromium-browser)
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
"$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --user-data-dir="$profile" --hide-scrollbars --window-size=1280,1180 \
  --screenshot="$PWD/docs/img/report-lakes.png" "file://$PWD/out/lakes.html#bars" 2>/dev/null
ls -l docs/img/report-lakes.png
