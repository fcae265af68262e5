#!/usr/bin/env bash
# Installs what the CityJSON tests need beside cjval (a dev-dependency crate): cjio, the
# CityJSON toolbox of TU Delft (PyPI), in a virtual environment of its own at
# target/cjio-venv, with which tests/cityjson.rs reads city.city.jsonl as a client would.
# Skipped when it is already there at the pinned version.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${CARGO_TARGET_DIR:-target}/cjio-venv
version=0.10.1
if [ -x "$venv/bin/cjio" ] && "$venv/bin/cjio" --version 2>/dev/null | grep -q "v$version"; then
  exit 0
fi
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet "cjio==$version"
"$venv/bin/cjio" --version
