#!/usr/bin/env bash
# Installs the system packages skeletonise needs (Debian/Ubuntu): GDAL ≥ 3.6 with its
# headers (the gdal crate links to it), pkg-config (to find it) and gdal-bin (ogrinfo).
# With --browser also Chromium, in which the report's test opens the report (tests/all/report.rs).
set -euo pipefail
need=()
command -v gdal-config >/dev/null 2>&1 || need+=(libgdal-dev)
command -v ogrinfo >/dev/null 2>&1 || need+=(gdal-bin)
command -v pkg-config >/dev/null 2>&1 || need+=(pkg-config)
command -v cc >/dev/null 2>&1 || need+=(build-essential)
if [ "${1:-}" = "--browser" ]; then
  command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || need+=(chromium)
fi
"$(dirname "$0")/apt-install.sh" "for the build" ${need[@]+"${need[@]}"}
