#!/usr/bin/env bash
# make crowd-fd: the fundamental diagram of our crowd against real walking (issue 41). Our
# boids (examples/crowd_corridor.rs, the city's [crowd] defaults) and JuPedSim walk the same
# corridor from the same start; PedPy measures both; Weidmann (1993) is drawn over them
# (scripts/crowd_fd.py). Prints the tables docs/crowds.md quotes and writes
# docs/pictures/crowd-fd.png. JuPedSim, PedPy and matplotlib go into a virtual environment
# this script makes (target/crowd-venv), pinned by scripts/crowd-fd-requirements.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-target}
venv=$target/crowd-venv
if ! "$venv/bin/python" -c 'import jupedsim, pedpy, matplotlib' 2>/dev/null; then
  python3 -m venv "$venv" 2>/dev/null || { source scripts/apt-install.sh; apt_install python3-venv; python3 -m venv "$venv"; }
  "$venv/bin/pip" install --quiet -r scripts/crowd-fd-requirements.txt
fi
cargo build --release --quiet --example crowd_corridor
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# A 60 x 4 m corridor (a street of 5 m less people.edge_margin each side), 25 s.
"$target/release/examples/crowd_corridor" "$work" 60 4 25
"$venv/bin/python" scripts/crowd_fd.py "$work" "${1:-docs/pictures/crowd-fd.png}" 60 4 25
