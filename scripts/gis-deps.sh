#!/usr/bin/env bash
# Installs what the GIS tests need, on a fresh machine: Debian's gdal-bin (ogrinfo,
# gdalsrsinfo) and python3-gdal (GDAL's GeoPackage validator), with which tests/gpkg.rs reads
# what a build writes for QGIS. Skipped when they are already there.
set -euo pipefail
cd "$(dirname "$0")/.."

# shellcheck source=scripts/apt-install.sh
. scripts/apt-install.sh
if ! command -v ogrinfo >/dev/null 2>&1 \
  || [ ! -f /usr/lib/python3/dist-packages/osgeo_utils/samples/validate_gpkg.py ]; then
  apt_install gdal-bin python3-gdal
fi
command -v ogrinfo >/dev/null
