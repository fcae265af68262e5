#!/usr/bin/env bash
# Builds a synthetic Kyoto of 30,052 lots (the paper's machiya count) three times and prints
# wall time, throughput, output size and peak RSS. Not part of `make test`: speed is measured
# here, never asserted in tests.
set -euo pipefail
cd "$(dirname "$0")/.."
LOTS=${LOTS:-30052}
RUNS=${RUNS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cargo build --release --quiet
bin=target/release/edo-city
$bin synth "$work/town" --lots "$LOTS" --seed 1
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB"
for i in $(seq 1 "$RUNS"); do
  rm -rf "$work/out"
  start=$(date +%s.%N)
  /usr/bin/time -f "%M" -o "$work/rss" $bin build "$work/town" --out "$work/out" --quiet --timings 2> "$work/timings"
  end=$(date +%s.%N)
  wall=$(echo "$end - $start" | bc -l)
  mb=$(du -sm --apparent-size "$work/out/tiles" | cut -f1)
  rss=$(( $(cat "$work/rss") / 1024 ))
  printf 'run %d: %.2f s, %.0f lots/s, %s MB tiles, %.0f MB/s, peak RSS %d MB | %s\n' \
    "$i" "$wall" "$(echo "$LOTS / $wall" | bc -l)" "$mb" "$(echo "$mb / $wall" | bc -l)" "$rss" \
    "$(grep timings "$work/timings")"
done
