# Imports a BVH file and a glTF binary with Blender's own importers, each into an empty scene, and
# prints what Blender made of each as one line "MOCAP_BLENDER {json}" for the test to read.
# Run headless:
#   blender --background --factory-startup --python blender_import_gltf.py -- FILE.bvh FILE.glb
# The GLB is imported at the BVH's frame rate (the scene's, which the BVH importer sets), so one
# key per frame lands on one scene frame each.
import json
import sys

import bpy

bvh_path, glb_path = sys.argv[sys.argv.index("--") + 1 :][:2]

# Debian's Blender 3.4.1 runs on Python 3.11, which no longer accepts the mode "rU" that the BVH
# importer opens the file with (tests/nodes/blender_import_bvh.py does the same).
import io_anim_bvh.import_bvh as import_bvh

_builtin_open = open


def _open_without_universal_newlines(file, mode="r", *args, **kwargs):
    return _builtin_open(file, mode.replace("U", ""), *args, **kwargs)


import_bvh.open = _open_without_universal_newlines

# Its glTF importer (io_import_scene_gltf2 of Blender 3.4) uses numpy.bool, an alias that Debian's
# numpy (1.24+) no longer has; it meant the builtin bool, so the alias is put back.
import numpy

if not hasattr(numpy, "bool"):
    numpy.bool = bool


def empty_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for action in list(bpy.data.actions):
        bpy.data.actions.remove(action)
    for armature in list(bpy.data.armatures):
        bpy.data.armatures.remove(armature)


def describe(result):
    scene = bpy.context.scene
    armatures = [o for o in scene.objects if o.type == "ARMATURE"]
    report = {"result": sorted(result), "armatures": len(armatures), "meshes": len(
        [o for o in scene.objects if o.type == "MESH"])}
    bones = 0
    keyed = set()
    keys_per_curve = 0
    for armature in armatures:
        bones += len(armature.data.bones)
        action = armature.animation_data.action if armature.animation_data else None
        if action:
            for curve in action.fcurves:
                keyed.update(round(k.co[0], 3) for k in curve.keyframe_points)
                keys_per_curve = max(keys_per_curve, len(curve.keyframe_points))
    report.update(bones=bones, keyed_frames=len(keyed), keys_per_curve=keys_per_curve,
                  fps=scene.render.fps / scene.render.fps_base)
    if armatures:
        report["first_bones"] = [b.name for b in armatures[0].data.bones][:3]
    return report


empty_scene()
bvh = describe(bpy.ops.import_anim.bvh(filepath=bvh_path, update_scene_fps=True,
                                       update_scene_duration=True))
empty_scene()
glb = describe(bpy.ops.import_scene.gltf(filepath=glb_path))
print("MOCAP_BLENDER " + json.dumps({"bvh": bvh, "glb": glb}), flush=True)
