#!/usr/bin/env bash
# Installs what the viewer's tests need, on a fresh machine: the npm packages exactly as
# viewer/package-lock.json pins them (three.js, 3d-tiles-renderer, CesiumJS, gltf-validator,
# playwright-core; `npm ci`, no browser download), and Debian's chromium, which
# playwright-core drives. Each step is skipped when it is already done.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -f viewer/node_modules/.package-lock.json ] \
  || [ viewer/package-lock.json -nt viewer/node_modules/.package-lock.json ]; then
  (cd viewer && npm ci --no-audit --no-fund)
fi

# shellcheck source=scripts/apt-install.sh
. scripts/apt-install.sh
if ! command -v chromium >/dev/null 2>&1; then
  apt_install chromium
fi
command -v chromium >/dev/null
