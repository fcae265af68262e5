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

if ! command -v faketime >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq faketime >/dev/null
  else
    sudo apt-get update -qq
    sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq faketime >/dev/null
  fi
fi
command -v faketime >/dev/null
