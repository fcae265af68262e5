#!/usr/bin/env bash
# Installs what `.ci/run` needs beyond the Rust toolchain, on a fresh machine: the lints
# (rustfmt, clippy) and Debian's faketime for the run of the suite a year ahead. Each step
# is skipped when its tool is already there; a tool that cannot be installed fails the run.
set -euo pipefail

if ! cargo fmt --version >/dev/null 2>&1 || ! cargo clippy --version >/dev/null 2>&1; then
  if command -v rustup >/dev/null 2>&1; then
    rustup component add rustfmt clippy
  fi
fi
cargo fmt --version >/dev/null
cargo clippy --version >/dev/null

# shellcheck source=scripts/apt-install.sh
. "$(dirname "$0")/apt-install.sh"
if ! command -v faketime >/dev/null 2>&1; then
  apt_install faketime
fi
command -v faketime >/dev/null

# GDAL reads what the build writes as GIS layers (tests/gpkg.rs): ogrinfo and gdalsrsinfo
# from gdal-bin, the GeoPackage validator from python3-gdal.
if ! command -v ogrinfo >/dev/null 2>&1 \
  || [ ! -f /usr/lib/python3/dist-packages/osgeo_utils/samples/validate_gpkg.py ]; then
  apt_install gdal-bin python3-gdal
fi
command -v ogrinfo >/dev/null
