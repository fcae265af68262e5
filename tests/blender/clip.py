"""Blender's own glTF importer on one tile: where each walker stands at the given times.

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/clip.py -- \
        <tile.glb> <t0> <t1> ...

Prints one line, `EDO_CITY_JSON {...}`: the scene's frame rate, the frame range the importer
set, and for every walker (an object or an armature's bone named `person_<id>`) its world
location (Blender's Z up: x east, y north of the tile's origin) and yaw (radians about Z) at
each time. tests/crowd_clip.rs compares them with crowds/<tile>.csv.
"""
import json
import math
import struct
import sys

import numpy as np

# Debian 12's Blender 3.4.1 importer calls np.bool, which NumPy 1.24 (Debian 12's own)
# removed: every mesh import fails with AttributeError without this alias.
if not hasattr(np, "bool"):
    np.bool = bool

import bpy  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
glb, times = argv[0], [float(t) for t in argv[1:]]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb)
scene = bpy.context.scene
fps = scene.render.fps / scene.render.fps_base
# A tile's walkers are the joints of its skinned crowd: the importer makes them bones of an
# armature. A bone's rest is its joint's node as the file places it (before the clip plays),
# turned by a correction of the importer's own (its bone heuristic); so the joint's heading
# at a time is the pose bone's turn from its rest plus the node's heading in the file (a
# turn about glTF's +y, which is Blender's +z). Its place is the bone's head.
walkers = {}
for o in bpy.data.objects:
    if o.name.startswith("person_"):
        walkers[o.name[len("person_"):]] = (o, None)
    if o.type == "ARMATURE":
        for pb in o.pose.bones:
            if pb.name.startswith("person_"):
                walkers[pb.name[len("person_"):]] = (o, pb)


def node_headings(path):
    """Each node's heading about +y in the GLB's JSON, by name."""
    with open(path, "rb") as f:
        data = f.read()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + length])
    out = {}
    for n in doc.get("nodes", []):
        x, y, z, w = n.get("rotation", [0, 0, 0, 1])
        out[n.get("name")] = 2 * math.atan2(y, w)
    return out


rest = node_headings(glb)


def place(o, pb):
    """(x, y, z, yaw) of an object or of a walker's bone, in the world."""
    if pb is None:
        m = o.matrix_world
        return list(m.translation) + [m.to_euler().z]
    m = o.matrix_world @ pb.matrix
    turn = (pb.matrix @ pb.bone.matrix_local.inverted()).to_euler().z
    return list(m.translation) + [turn + rest[pb.name]]


at = {name: [] for name in walkers}
for t in times:
    frame = t * fps
    scene.frame_set(int(frame), subframe=frame - int(frame))
    for name, (o, pb) in walkers.items():
        at[name].append(place(o, pb))
out = {
    "fps": fps,
    "frames": [scene.frame_start, scene.frame_end],
    "objects": len(bpy.data.objects),
    "at": at,
}
print("EDO_CITY_JSON " + json.dumps(out))
