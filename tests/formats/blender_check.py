"""Blender (headless) imports a file Stylus wrote and reports what it got.

blender -b --factory-startup --python blender_check.py -- IN.glb|IN.fbx OUT.txt FRAME FPS

The scene runs at FPS (Blender's importers key glTF at the scene's rate).
Writes OUT.txt, one fact per line: "armatures N", "meshes N", "frames N"
(the animation's frame count) and "head BONE X Y Z" for each bone: its head in
world space at FRAME (the file's first frame is 0), turned back to Y-up
(Blender's importers turn Y-up files to Z-up).
"""
import sys

import bpy
import numpy

# Debian's Blender 3.4 glTF importer still says numpy.bool, which Debian's
# numpy 1.24 no longer has.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

argv = sys.argv[sys.argv.index("--") + 1:]
path, out, frame, fps = argv[0], argv[1], int(argv[2]), int(argv[3])
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.context.scene.render.fps = fps
if path.lower().endswith(".fbx"):
    bpy.ops.import_scene.fbx(filepath=path)
elif path.lower().endswith(".dae"):
    bpy.ops.wm.collada_import(filepath=path)
else:
    bpy.ops.import_scene.gltf(filepath=path)
arms = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]
lines = ["armatures %d" % len(arms),
         "meshes %d" % len([o for o in bpy.context.scene.objects if o.type == "MESH"])]
if arms:
    arm = arms[0]
    action = arm.animation_data.action if arm.animation_data else None
    first, last = (action.frame_range if action else (0, 0))
    lines.append("frames %d" % (int(round(last - first)) + 1))
    bpy.context.scene.frame_set(int(round(first)) + frame)
    for bone in arm.pose.bones:
        p = arm.matrix_world @ bone.head
        lines.append("head %s %.9g %.9g %.9g" % (bone.name, p.x, p.z, -p.y))
with open(out, "w") as f:
    f.write("\n".join(lines) + "\n")
