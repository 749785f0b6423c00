#!/usr/bin/env bash
# Installs what the tests need beyond the build (Debian/Ubuntu): PostgreSQL with PostGIS for the
# test that reads a real PostGIS source (tests/all/postgis.rs starts a throw-away cluster itself).
set -euo pipefail
need=()
ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1 || need+=(postgresql)
command -v psql >/dev/null 2>&1 || need+=(postgresql-client)
dpkg -s postgis >/dev/null 2>&1 || ls /usr/share/postgresql/*/extension/postgis.control >/dev/null 2>&1 || need+=(postgis)
"$(dirname "$0")/apt-install.sh" "for the tests" ${need[@]+"${need[@]}"}
