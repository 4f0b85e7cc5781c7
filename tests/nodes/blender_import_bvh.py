# Imports a BVH file with Blender's own importer and prints what Blender made of it, as one line
# "MOCAP_BLENDER {json}" for the test to read. Run headless:
#   blender --background --factory-startup --python blender_import_bvh.py -- FILE.bvh
import json
import sys

import bpy

path = sys.argv[sys.argv.index("--") + 1]

# Debian's Blender 3.4.1 runs on Python 3.11, which no longer accepts the mode "rU" that this
# importer opens the file with. Its module gets an open() that drops the "U"; the parsing is
# Blender's own, unchanged.
import io_anim_bvh.import_bvh as import_bvh

_builtin_open = open


def _open_without_universal_newlines(file, mode="r", *args, **kwargs):
    return _builtin_open(file, mode.replace("U", ""), *args, **kwargs)


import_bvh.open = _open_without_universal_newlines
result = bpy.ops.import_anim.bvh(filepath=path, update_scene_fps=True, update_scene_duration=True)
armatures = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]
report = {"result": sorted(result), "armatures": len(armatures)}
if armatures:
    armature = armatures[0]
    action = armature.animation_data.action if armature.animation_data else None
    keyed_frames = set()
    if action:
        for curve in action.fcurves:
            keyed_frames.update(round(k.co[0]) for k in curve.keyframe_points)
    scene = bpy.context.scene
    report.update(
        bones=len(armature.data.bones),
        bone_names=[b.name for b in armature.data.bones],
        keyed_frames=len(keyed_frames),
        frame_start=scene.frame_start,
        frame_end=scene.frame_end,
        fps=scene.render.fps / scene.render.fps_base,
    )
print("MOCAP_BLENDER " + json.dumps(report), flush=True)
