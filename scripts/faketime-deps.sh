#!/usr/bin/env bash
# Installs Debian's faketime on a fresh machine: `make test` runs the suite under it on a day
# a year ahead (scripts/test-future.sh). Skipped when it is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

# shellcheck source=scripts/apt-install.sh
. scripts/apt-install.sh
if ! command -v faketime >/dev/null 2>&1; then
  apt_install faketime
fi
command -v faketime >/dev/null
