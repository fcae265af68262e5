#!/usr/bin/env bash
# make bench: towns of the composition users build (`synth --profile kyoto`: estates with
# their halls, kura behind half the houses, long walls, repeated ids): the paper's scale
# (30,052 lots) three times, the scaling at 7,500 / 30,052 / 120,000 lots, single-tile
# regeneration, the raw write of the same bytes as the limit, and the paired runs against the
# box-extrusion script. Speed is measured here, never asserted in tests. Results go into
# BENCHMARKS.md by hand.
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cargo build --release --quiet --example raw_write
cargo build --release --quiet
bin=${CARGO_TARGET_DIR:-target}/release/edo-city
# The analysis cache of the builds below stays in the scratch directory, not in ~/.cache.
export EDO_CITY_CACHE="$work/cache"
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB; $(rustc --version)"

# build LOTS RUN: one timed build into $work/out-LOTS, one result line.
build() {
  local lots=$1 run=$2 out="$work/out-$1"
  rm -rf "$out"
  local start end wall mb rss
  start=$(date +%s.%N)
  /usr/bin/time -f "%M" -o "$work/rss" $bin build "$work/town-$lots" --out "$out" --quiet --timings 2> "$work/timings"
  end=$(date +%s.%N)
  wall=$(echo "$end - $start" | bc -l)
  mb=$(du -sm --apparent-size "$out/tiles" | cut -f1)
  rss=$(( $(cat "$work/rss") / 1024 ))
  printf '%7d lots run %d: %6.2f s %8.0f lots/s %5s MB tiles %6.0f MB/s  peak RSS %5d MB | %s\n' \
    "$lots" "$run" "$wall" "$(echo "$lots / $wall" | bc -l)" "$mb" "$(echo "$mb / $wall" | bc -l)" "$rss" \
    "$(sed -n 's/^timings: //p' "$work/timings")"
}

for lots in 30052 7500 120000; do
  $bin synth "$work/town-$lots" --lots "$lots" --seed 1 --profile kyoto > /dev/null
done
echo "== the paper's scale"
for i in $(seq 1 "$RUNS"); do build 30052 "$i"; done
echo "== scaling"
build 7500 1
build 120000 1

echo "== the limit: raw fixed-point write of the same bytes (30,052 lots)"
bytes=$(du -sb --apparent-size "$work/out-30052/tiles" | cut -f1)
raw=$(${CARGO_TARGET_DIR:-target}/release/examples/raw_write "$bytes" "$work/raw.obj")
rm -f "$work/raw.obj"
echo "tiles: $bytes bytes; raw write: $raw s ($(echo "$bytes / $raw / 1000000" | bc -l | cut -c1-6) MB/s)"

echo "== the formats (30,052 lots): OBJ only, GLB only, both (the default above)"
for f in obj glb; do
  rm -rf "$work/out-$f"
  /usr/bin/time -f "%e s, peak RSS %M KB" -o "$work/rss" $bin build "$work/town-30052" --out "$work/out-$f" --quiet --timings --format "$f" 2> "$work/timings"
  printf '%s: %s | %s\n' "$f" "$(cat "$work/rss")" "$(sed -n 's/^timings: //p' "$work/timings")"
done
python3 -c "
import json; r = json.load(open('$work/out-30052/report.json')); t = r['tiles']
g = max(t, key=lambda x: x['glb_bytes'])
print('tiles', len(t), '| OBJ', round(sum(x['obj_bytes'] for x in t) / 1e6, 1), 'MB, GLB', round(sum(x['glb_bytes'] for x in t) / 1e6, 1), 'MB | densest GLB', g['id'], g['glb_bytes'], 'bytes (its OBJ', g['obj_bytes'], ')')"

echo "== single-tile regeneration (30,052 lots, the largest tile)"
tile=$(python3 -c "import json,sys; r=json.load(open('$work/out-30052/report.json')); print(max(r['tiles'], key=lambda t: t['obj_bytes'])['id'])")
for cache in "$EDO_CITY_CACHE" off; do
  for i in $(seq 1 "$RUNS"); do
    start=$(date +%s.%N)
    EDO_CITY_CACHE=$cache $bin build "$work/town-30052" --out "$work/out-30052" --tiles "$tile" --quiet
    end=$(date +%s.%N)
    printf 'tile %s run %d, analysis cache %s: %.3f s\n' "$tile" "$i" \
      "$([ "$cache" = off ] && echo off || echo on)" "$(echo "$end - $start" | bc -l)"
  done
done

echo "== the crowd model (edo-city boids, 100 steps, order parameters at every step)"
for agents in 10 1000 10000; do
  start=$(date +%s.%N)
  $bin boids --agents "$agents" --steps 100 --width 5000 --height 3000 --csv "$work/boids.csv" > /dev/null
  end=$(date +%s.%N)
  printf '%6d agents: %.3f s for 100 steps\n' "$agents" "$(echo "$end - $start" | bc -l)"
done

echo "== street crowds in the city (30,052 lots, people.motion = \"boids\"; compare the people and trees figure with the default runs above)"
printf '[people]\nmotion = "boids"\n' > "$work/boids.toml"
for i in $(seq 1 "$RUNS"); do
  $bin build "$work/town-30052" --out "$work/out-boids" --params "$work/boids.toml" --quiet --force --timings 2>&1 \
    | sed -n "s/^timings: /run $i: /p"
done

echo "== the growers (examples/bench_growers.rs: colonization at 2,000 and 20,000 points, the garden GA, each species' skeleton and LODs)"
cargo run --release --quiet --example bench_growers

echo "== grown trees in the city (30,052 lots; trees.style; compare with the default runs above, which have billboards)"
for style in lsystem colonization; do
  printf '[trees]\nstyle = "%s"\n' "$style" > "$work/$style.toml"
  rm -rf "$work/out-$style"
  start=$(date +%s.%N)
  $bin build "$work/town-30052" --out "$work/out-$style" --params "$work/$style.toml" --quiet
  end=$(date +%s.%N)
  printf '%-12s %.2f s, %s MB of tiles, largest tile %s bytes\n' "$style" "$(echo "$end - $start" | bc -l)" \
    "$(du -sm --apparent-size "$work/out-$style/tiles" | cut -f1)" \
    "$(python3 -c "import json; r=json.load(open('$work/out-$style/report.json')); print(max(t['obj_bytes'] for t in r['tiles']))")"
done

echo "== rock gardens in the city (30,052 lots, garden.enabled = false against the default runs above)"
printf '[garden]\nenabled = false\n' > "$work/nogarden.toml"
for i in $(seq 1 "$RUNS"); do
  start=$(date +%s.%N)
  $bin build "$work/town-30052" --out "$work/out-nogarden" --params "$work/nogarden.toml" --quiet --force
  end=$(date +%s.%N)
  printf 'no gardens run %d: %.2f s\n' "$i" "$(echo "$end - $start" | bc -l)"
done

echo "== ground and halls (30,052 lots, ground and halls off against the default runs above)"
printf '[ground]\nenabled = false\n[halls]\nenabled = false\n' > "$work/bare.toml"
for i in $(seq 1 "$RUNS"); do
  start=$(date +%s.%N)
  $bin build "$work/town-30052" --out "$work/out-bare" --params "$work/bare.toml" --quiet --force
  end=$(date +%s.%N)
  printf 'no ground, no halls run %d: %.2f s\n' "$i" "$(echo "$end - $start" | bc -l)"
done
python3 -c "
import json, collections; r = json.load(open('$work/out-30052/report.json')); t = r['tiles']
g = [x['ground_bytes'] for x in t]
print('ground bytes per tile (OBJ): mean', round(sum(g) / len(g)), 'max', max(g), '| of the tiles', round(100 * sum(g) / sum(x['obj_bytes'] for x in t), 2), '%')
print('halls:', dict(collections.Counter((h['template'], 'placed' if h['placed'] else 'skipped') for h in r.get('halls', []))))"

echo "== against the box-extrusion script (30,052 lots; scripts/box_extrude.py, pyshp; 5 runs of each, alternating)"
echo "   default: build as README gives it; obj: --format obj; all: every feature (lsystem trees, boids), default formats"
# pyshp in a virtual environment of our own (kept beside the release build, made once):
# never the system's Python.
venv=${CARGO_TARGET_DIR:-target}/bench-venv
if ! "$venv/bin/python" -c 'import shapefile' 2>/dev/null; then
  python3 -m venv "$venv" 2>/dev/null || { source scripts/apt-install.sh; apt_install python3-venv; python3 -m venv "$venv"; }
  "$venv/bin/pip" install --quiet pyshp
fi
cargo build --release --quiet --example raw_write
printf '[trees]\nstyle = "lsystem"\n[people]\nmotion = "boids"\n' > "$work/all.toml"
: > "$work/ab.txt"
for i in $(seq 1 5); do
  for what in script default obj all; do
    rm -rf "$work/ab-$what"
    start=$(date +%s.%N)
    case $what in
      script) "$venv/bin/python" scripts/box_extrude.py "$work/town-30052/lots.shp" "$work/box.obj" ;;
      default) $bin build "$work/town-30052" --out "$work/ab-$what" --quiet ;;
      obj) $bin build "$work/town-30052" --out "$work/ab-$what" --quiet --format obj ;;
      all) $bin build "$work/town-30052" --out "$work/ab-$what" --quiet --params "$work/all.toml" ;;
    esac
    end=$(date +%s.%N)
    case $what in
      script) bytes=$(stat -c %s "$work/box.obj") ;;
      *) bytes=$(du -sb --apparent-size "$work/ab-$what/tiles" | cut -f1) ;;
    esac
    raw=$(${CARGO_TARGET_DIR:-target}/release/examples/raw_write "$bytes" "$work/raw.obj")
    rm -f "$work/raw.obj"
    echo "$what $(echo "$end - $start" | bc -l) $bytes $raw" >> "$work/ab.txt"
  done
done
python3 - "$work/ab.txt" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
by = {}
for what, wall, size, raw in rows:
    by.setdefault(what, []).append((float(wall), int(size), float(raw)))
med = {w: statistics.median(r[0] for r in v) for w, v in by.items()}
for w, v in by.items():
    walls = sorted(r[0] for r in v)
    raw = statistics.median(r[2] for r in v)
    print(f"{w:8s} median {med[w]:.2f} s ({walls[0]:.2f}-{walls[-1]:.2f}), {v[0][1] / 1e6:.1f} MB, "
          f"raw write of those bytes {raw:.2f} s -> {med[w] / raw:.1f}x the raw write")
print(f"default / script: {med['default'] / med['script']:.2f} (target 2.5); "
      f"OBJ / script: {med['obj'] / med['script']:.2f} (target 1.5); "
      f"every feature: {med['all']:.2f} s (target 6 s)")
PY

echo "== the workbench (issue 61): an edit's POST to its answer on 30,052 lots"
python3 scripts/bench_workbench.py "$bin" "$work/town-30052" "$work/workbench" 3
