#!/usr/bin/env bash
# Installs Debian/Ubuntu packages (as root, or with sudo), quietly: apt-install.sh WHY PKG...
# WHY says in the log what they are for. Nothing happens without packages.
set -euo pipefail
why=$1
shift
[ $# -gt 0 ] || exit 0
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "installing $why: $*" >&2
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "$@" >/dev/null
