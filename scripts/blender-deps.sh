#!/usr/bin/env bash
# Installs Debian's blender (3.4.1 on Debian 12: 22 MB to fetch, 87 MB installed) on a fresh
# machine: tests/crowd_clip.rs imports a tile with Blender's own glTF importer and checks the
# walkers' clip against crowds/<tile>.csv. Skipped when it is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

# shellcheck source=scripts/apt-install.sh
. scripts/apt-install.sh
if ! command -v blender >/dev/null 2>&1; then
  apt_install blender
fi
command -v blender >/dev/null
