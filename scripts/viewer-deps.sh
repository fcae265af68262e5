#!/usr/bin/env bash
# Installs what the viewer's tests need, on a fresh machine: the npm packages exactly as
# viewer/package-lock.json pins them (three.js, 3d-tiles-renderer, gltf-validator,
# playwright-core; `npm ci`, no browser download), and Debian's chromium, which
# playwright-core drives. Each step is skipped when it is already done.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -f viewer/node_modules/.package-lock.json ] \
  || [ viewer/package-lock.json -nt viewer/node_modules/.package-lock.json ]; then
  (cd viewer && npm ci --no-audit --no-fund)
fi

if ! command -v chromium >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
  else
    sudo apt-get update -qq
    sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
  fi
fi
command -v chromium >/dev/null
