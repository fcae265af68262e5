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

bash "$(dirname "$0")/faketime-deps.sh"
