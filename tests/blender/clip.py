"""Blender's own glTF importer on one tile: where each walker stands at the given times.

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/clip.py -- \
        <tile.glb> <t0> <t1> ...

Prints one line, `EDO_CITY_JSON {...}`: the scene's frame rate, the frame range the importer
set, and for every object named `person_<id>` its world location (Blender's Z up: x east,
y north of the tile's origin) and yaw (radians about Z) at each time. tests/crowd_clip.rs
compares them with crowds/<tile>.csv.
"""
import json
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
walkers = {o.name[len("person_"):]: o for o in bpy.data.objects if o.name.startswith("person_")}
at = {name: [] for name in walkers}
for t in times:
    frame = t * fps
    scene.frame_set(int(frame), subframe=frame - int(frame))
    for name, o in walkers.items():
        m = o.matrix_world
        at[name].append(list(m.translation) + [m.to_euler().z])
out = {
    "fps": fps,
    "frames": [scene.frame_start, scene.frame_end],
    "objects": len(bpy.data.objects),
    "at": at,
}
print("EDO_CITY_JSON " + json.dumps(out))
