#!/usr/bin/env bash
# Installs the system packages skeletonise needs (Debian/Ubuntu): GDAL ≥ 3.6 with its
# headers (the gdal crate links to it), pkg-config (to find it) and gdal-bin (ogrinfo).
set -euo pipefail
need=()
command -v gdal-config >/dev/null 2>&1 || need+=(libgdal-dev)
command -v ogrinfo >/dev/null 2>&1 || need+=(gdal-bin)
command -v pkg-config >/dev/null 2>&1 || need+=(pkg-config)
command -v cc >/dev/null 2>&1 || need+=(build-essential)
if [ ${#need[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "installing: ${need[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${need[@]}" >/dev/null
fi
