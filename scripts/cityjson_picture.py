"""Renders a CityJSONSeq as docs/cityjson.md shows it: every city object's most detailed
geometry, coloured by what the model says it is (a building's roofs red, walls pale, its
ground dark; installations blue; walls and gates grey; the rock garden green; ground and
roads as they lie; trees from their templates), seen from above the south-east.

    blender -b --python scripts/cityjson_picture.py -- OUT/city.city.jsonl PICTURE.png [TILE]

TILE (a tile id, e.g. 1108_760) keeps only the objects of that tile's fragment lines (the
objects whose ids end in -TILE, and the buildings and trees inside that tile's box).
"""
import json
import math
import sys

import bpy

COLOURS = {
    "RoofSurface": (0.62, 0.16, 0.12),
    "WallSurface": (0.9, 0.87, 0.8),
    "GroundSurface": (0.25, 0.22, 0.2),
    "OuterCeilingSurface": (0.45, 0.4, 0.35),
    "OuterFloorSurface": (0.7, 0.65, 0.55),
    "BuildingInstallation": (0.2, 0.35, 0.75),
    "CityFurniture": (0.55, 0.55, 0.55),
    "PlantCover": (0.35, 0.6, 0.3),
    "SolitaryVegetationObject": (0.2, 0.45, 0.2),
    "LandUse": (0.78, 0.74, 0.62),
    "Road": (0.6, 0.58, 0.55),
    "TINRelief": (0.7, 0.7, 0.6),
}


def material(name):
    m = bpy.data.materials.get(name)
    if m is None:
        m = bpy.data.materials.new(name)
        m.diffuse_color = (*COLOURS[name], 1.0)
    return m


def main(path, picture, tile=None):
    lines = open(path, encoding="utf-8").read().splitlines()
    header = json.loads(lines[0])
    scale = header["transform"]["scale"]
    templates = header.get("geometry-templates", {})
    tverts = templates.get("vertices-templates", [])
    verts, faces, mats = [], [], []
    names = list(COLOURS)

    def add(points, ring_lists, kinds):
        base = len(verts)
        verts.extend(points)
        for ring, kind in zip(ring_lists, kinds):
            if len(ring) >= 3:
                faces.append([base + i for i in ring])
                mats.append(names.index(kind))

    def rings(g):
        b = g["boundaries"]
        if g["type"] == "Solid":
            return [s[0] for shell in b for s in shell], [v for shell in g.get("semantics", {}).get("values", [[None] * len(b[0])]) for v in shell]
        return [s[0] for s in b], g.get("semantics", {}).get("values", [None] * len(b))

    for line in lines[1:]:
        f = json.loads(line)
        pts = [[v[k] * scale[k] for k in range(3)] for v in f["vertices"]]
        for oid, o in f["CityObjects"].items():
            if tile and not oid.endswith("-" + tile) and o["type"] not in ("Building", "BuildingInstallation", "SolitaryVegetationObject"):
                continue
            geoms = o.get("geometry", [])
            if not geoms:
                continue
            g = geoms[-1]
            if g["type"] == "GeometryInstance":
                t = templates["templates"][g["template"]]
                m = g["transformationMatrix"]
                ref = pts[g["boundaries"][0]]
                tp = [[m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + ref[r] for r in range(3)] for p in tverts]
                rs = [s[0] for s in t["boundaries"]]
                add(tp, rs, ["SolitaryVegetationObject"] * len(rs))
                continue
            rs, values = rings(g)
            sem = g.get("semantics", {}).get("surfaces", [])
            if o["type"] in ("Building",):
                kinds = [sem[v]["type"] if v is not None and sem else "WallSurface" for v in values]
            else:
                kinds = [o["type"]] * len(rs)
            add(pts, rs, kinds)
    if tile:
        # Keep the buildings and trees inside the tile's own ground.
        ground = [i for i, k in enumerate(mats) if names[k] in ("LandUse", "Road")]
        xs = [verts[v][0] for i in ground for v in faces[i]]
        ys = [verts[v][1] for i in ground for v in faces[i]]
        box = (min(xs), min(ys), max(xs), max(ys))
        keep = [i for i, fc in enumerate(faces) if all(box[0] <= verts[v][0] <= box[2] and box[1] <= verts[v][1] <= box[3] for v in fc)]
        faces = [faces[i] for i in keep]
        mats = [mats[i] for i in keep]
    mesh = bpy.data.meshes.new("city")
    mesh.from_pydata(verts, [], faces)
    for n in names:
        mesh.materials.append(material(n))
    for p, k in zip(mesh.polygons, mats):
        p.material_index = k
    obj = bpy.data.objects.new("city", mesh)
    bpy.context.scene.collection.objects.link(obj)
    used = {v for fc in faces for v in fc}
    xs = [verts[v][0] for v in used]
    ys = [verts[v][1] for v in used]
    cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
    size = max(max(xs) - min(xs), max(ys) - min(ys))
    cam = bpy.data.cameras.new("cam")
    cam.lens = 50
    cam_obj = bpy.data.objects.new("cam", cam)
    bpy.context.scene.collection.objects.link(cam_obj)
    d = size * 0.95
    cam_obj.location = (cx + d * 0.55, cy - d * 0.75, d * 0.75)
    direction = (cx - cam_obj.location[0], cy - cam_obj.location[1], -cam_obj.location[2])
    cam_obj.rotation_euler = (
        math.atan2(math.hypot(direction[0], direction[1]), -direction[2]),
        0.0,
        math.atan2(direction[1], direction[0]) - math.pi / 2,
    )
    scene = bpy.context.scene
    scene.camera = cam_obj
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "MATERIAL"
    scene.display.shading.show_cavity = True
    scene.render.resolution_x, scene.render.resolution_y = 960, 600
    scene.render.film_transparent = False
    scene.world = bpy.data.worlds.new("sky") if scene.world is None else scene.world
    scene.world.color = (0.85, 0.87, 0.9)
    scene.display.shading.background_type = "WORLD"
    scene.render.filepath = picture
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:]
    main(*args)
