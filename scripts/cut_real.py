"""Writes fixtures/real/: the small, licence-clean cuts of ../shared/data/real that the real-data
tests run on in a clone with nothing beside it (issue 58). `make real-cut` runs it (pyshp in a
virtual environment of its own); tests/real_data.rs takes the full set in ../shared when it is
there and this cut otherwise, with the same assertions.

What is cut, and how (only the layers params/examples/ read):
- chino_plateau_devpermit: lots, districts, landmarks and road centre lines as they are;
  the 9,909 split lines with their geometry and the fields a build reads (object_id,
  road_width, roadway_wi): their 254-character label_text (2.5 MB of the DBF) is left out.
- osaka_plateau: buildings and road surfaces of both variants, as they are.
- kyoto_plateau_related: the zone VI emergency routes and parks, as they are.
Swellendam is not cut: its repository is GPL-2.0 and its content ODbL (OpenStreetMap) and
a surveyor-general's cadastre, which this project's licence cannot carry; its test runs
where ../shared is.

    python3 scripts/cut_real.py ../shared/data/real fixtures/real
"""
import os
import shutil
import sys

import shapefile

SIDECARS = (".shp", ".shx", ".dbf", ".prj", ".cpg")

AS_THEY_ARE = {
    "chino_plateau_devpermit": [
        "f_lot_number/f_lot_number",
        "f_district/f_district",
        "landmark/landmark",
        "road_layers/f_road_center_line/f_road_center_line",
    ],
    "osaka_plateau": [
        "jgd2011_geo_utf8/buildings",
        "jgd2011_geo_utf8/road_surfaces",
        "jgd2011_zone6_sjis/buildings",
        "jgd2011_zone6_sjis/road_surfaces",
    ],
    "kyoto_plateau_related": [
        "jgd2011_zone6_sjis/emergency_route",
        "jgd2011_zone6_sjis/park",
    ],
}

# Layers rewritten with some of their fields: (set, layer, fields kept).
FIELDS = [
    (
        "chino_plateau_devpermit",
        "road_layers/f_split_line/f_split_line",
        ["object_id", "road_width", "roadway_wi"],
    ),
]


def copy_layer(src, dst):
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    for ext in SIDECARS:
        if os.path.exists(src + ext):
            shutil.copyfile(src + ext, dst + ext)


def cut_fields(src, dst, keep):
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    encoding = "cp932"
    if os.path.exists(src + ".cpg"):
        encoding = {"shift_jis": "cp932", "utf-8": "utf-8"}.get(
            open(src + ".cpg").read().strip().lower(), "cp932"
        )
    r = shapefile.Reader(src, encoding=encoding)
    fields = [f for f in r.fields[1:] if f[0] in keep]
    with shapefile.Writer(dst, shapeType=r.shapeType, encoding=encoding) as w:
        for f in fields:
            w.field(*f)
        for sr in r.iterShapeRecords():
            w.shape(sr.shape)
            w.record(*[sr.record[f[0]] for f in fields])
    for ext in (".prj", ".cpg"):
        if os.path.exists(src + ext):
            shutil.copyfile(src + ext, dst + ext)


def main(real, out):
    for name, layers in AS_THEY_ARE.items():
        for layer in layers:
            copy_layer(os.path.join(real, name, layer), os.path.join(out, name, layer))
    for name, layer, keep in FIELDS:
        cut_fields(os.path.join(real, name, layer), os.path.join(out, name, layer), keep)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
