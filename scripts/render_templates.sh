#!/usr/bin/env bash
# Renders every shipped template alone into docs/templates/<name>.png, and a street of the
# example city with its people into docs/people.png (run `make pictures`).
# Needs f3d and xvfb-run (Debian: apt install f3d xvfb) and Blender (make blender-deps);
# the pictures are committed.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${CARGO_TARGET_DIR:-target}/release/edo-city
cargo build --release --quiet
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
render() { # name width depth camera-position focal-point
    local name=$1 w=$2 d=$3 cam=$4 focus=$5
    "$bin" template "$name" --width "$w" --depth "$d" -o "$work/$name.obj" >/dev/null
    xvfb-run -a f3d "$work/$name.obj" --output "docs/templates/$name.png" \
        --resolution 480,360 --camera-position="$cam" --camera-focal-point="$focus" \
        --camera-view-up=0,1,0 --grid=0 --bg-color=0.85,0.87,0.9 >/dev/null 2>&1
    echo "docs/templates/$name.png"
}
for t in hiraya naka-nikai-small naka-nikai-large sou-nikai sangai shimoutaya heitsuki kanban-gatera; do
    render "$t" 5.454 20 -13,11,19 2.7,4,-5
done
render kura 4.5 6.5 -7,7,10 2.2,2.8,-3.2
render fence 5.454 1 -3,3,7 2.7,0.9,0
render tsuiji 5.454 1 -3,4,8 2.7,1.3,0
render gate 3.03 1 -3,4,7 1.5,2,0
render tree 1 1 -8,4,15 0,3.4,0
render person 1 1 -1.5,1.5,3 0,0.8,0
# Halls on the plots they ask for (u east, v north: the gate side faces the camera).
render hondo 24 18 -12,14,16 12,4,-9
render sanmon 14 8 -13,13,19 7,5,-4
render goju-no-to 13 13 -32,18,44 6.5,14,-6.5
render omoya 22 18 -18,16,22 11,3,-9
render shinden 38 28 -18,24,26 19,3,-14

# The bundled example city at street level, with its people (README, "People
# and trees").
"$bin" build fixtures/kyoto-small --out "$work/city" --no-plan >/dev/null
xvfb-run -a f3d "$work/city/tiles/1108_760.obj" --output docs/people.png \
    --resolution 960,600 --camera-position=131,3,-185 --camera-focal-point=133,1.5,-205 \
    --camera-view-up=0,1,0 --grid=0 --bg-color=0.7,0.8,0.9 >/dev/null 2>&1
echo docs/people.png

# The example city as a CityJSON model, coloured by what the model says each surface is
# (docs/cityjson.md); Blender in the background (make blender-deps).
"$bin" build fixtures/kyoto-small --out "$work/model" --no-plan --format cityjson >/dev/null
blender -b --python scripts/cityjson_picture.py -- "$work/model/city.city.jsonl" \
    "$PWD/docs/pictures/cityjson.png" >/dev/null 2>&1
echo docs/pictures/cityjson.png
