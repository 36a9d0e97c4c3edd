"""Inside Blender (headless): the Stylus add-on, installed from its zip,
restyles a BVH-imported and an FBX-imported armature through a real server;
each new action is compared with the stylus CLI's transfer of the same clip.

blender -b --factory-startup --python blender_addon_check.py -- \
    ADDON.zip SERVER RIG.bvh STYLE.bvh CLI_OUT.bvh RIG.fbx CLI_FBX_OUT.bvh RIG.glb CLI_GLB_OUT.bvh \
    WORK_DIR REPORT.txt

RIG.fbx and RIG.glb are Blender's own exports of RIG.bvh
(tests/formats/blender_export.py); the CLI_*OUT.bvh files are the stylus
CLI's transfers of the three.

REPORT.txt gets one line per fact: "<case> <key> <value>".
"""
import builtins
import math
import os
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
(addon_zip, server, rig, style, cli_out, rig_fbx, cli_fbx_out, rig_glb, cli_glb_out, work,
 report_path) = argv
report = open(report_path, "w")


def fact(case, key, value):
    report.write("%s %s %s\n" % (case, key, value))
    report.flush()


# Debian's Blender 3.4 on Python 3.11: its BVH importer opens files with 'rU'.
import io_anim_bvh.import_bvh as import_bvh  # noqa: E402
import_bvh.open = lambda path, mode="r", *a, **k: builtins.open(path, mode.replace("U", ""), *a, **k)

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.preferences.addon_install(filepath=addon_zip, overwrite=True)
bpy.ops.preferences.addon_enable(module="stylus_blender")
fact("addon", "enabled", int("stylus_blender" in bpy.context.preferences.addons))


def import_bvh_file(path):
    before = set(bpy.data.objects)
    bpy.ops.import_anim.bvh(filepath=path, update_scene_fps=True, update_scene_duration=True)
    arm = next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")
    first, last = (int(round(f)) for f in arm.animation_data.action.frame_range)
    bpy.context.scene.frame_start, bpy.context.scene.frame_end = first, last
    return arm


def aligned_rotations(arm, frame):
    """Per bone: the world-aligned rotation (pose relative to rest, armature space)."""
    bpy.context.scene.frame_set(frame)
    out = {}
    for pb in arm.pose.bones:
        rest = pb.bone.matrix_local.to_3x3().normalized()
        out[pb.name] = (pb.matrix.to_3x3().normalized() @ rest.transposed()).to_quaternion()
    root = arm.pose.bones[0]
    return out, arm.matrix_world @ root.head


def angle_between(a, b):
    # From the difference's vector part: Quaternion.angle (2 acos w, in
    # mathutils' single precision) cannot tell angles below ~5e-4 rad from 0.
    d = a.rotation_difference(b)
    return 2 * math.asin(min(1.0, math.sqrt(d.x * d.x + d.y * d.y + d.z * d.z)))


def pose_heads(arm, frame):
    bpy.context.scene.frame_set(frame)
    return {pb.name: arm.matrix_world @ pb.head for pb in arm.pose.bones}


def compare(case, arm, reference, first, ref_first, frames):
    """Per bone and frame, against the reference: the rotation relative to
    rest (meaningful where both armatures share a rest pose), and the
    direction from the bone's head to its first child's (whatever the rest)."""
    worst = worst_dir = worst_root = 0.0
    worst_bone = worst_dir_bone = ""
    first_child = {b.name: b.children[0].name for b in reference.data.bones if b.children}
    for f in range(frames):
        got, root = aligned_rotations(arm, first + f)
        got_heads = pose_heads(arm, first + f)
        want, want_root = aligned_rotations(reference, ref_first + f)
        want_heads = pose_heads(reference, ref_first + f)
        for name, q in want.items():
            angle = angle_between(q, got[name])
            if angle > worst:
                worst, worst_bone = angle, "%s@%d" % (name, f)
            child = first_child.get(name)
            if child is None:
                continue
            a = want_heads[child] - want_heads[name]
            b = got_heads[child] - got_heads[name]
            d = math.atan2(a.cross(b).length, a.dot(b))
            if d > worst_dir:
                worst_dir, worst_dir_bone = d, "%s@%d" % (name, f)
        worst_root = max(worst_root, (root - want_root).length)
    fact(case, "max_rotation_difference_rad", "%.3g" % worst)
    fact(case, "worst_bone", worst_bone or "-")
    fact(case, "max_bone_direction_difference_rad", "%.3g" % worst_dir)
    fact(case, "worst_direction_bone", worst_dir_bone or "-")
    fact(case, "max_root_difference", "%.3g" % worst_root)


def restyle(case, arm):
    scene = bpy.context.scene
    for o in bpy.context.selected_objects:
        o.select_set(False)
    bpy.context.view_layer.objects.active = arm
    arm.select_set(True)
    s = scene.stylus
    s.server, s.style_source, s.style_file = server, "FILE", style
    s.strength, s.postprocess, s.timing = 1.0, "default", "content"
    original = arm.animation_data.action
    start = time.monotonic()
    result = bpy.ops.stylus.restyle()
    total = time.monotonic() - start
    new = arm.animation_data.action
    fact(case, "result", result.pop())
    fact(case, "new_action", new.name)
    fact(case, "original_kept", int(original.name in bpy.data.actions and original.use_fake_user))
    keyed = {fc.group.name for fc in new.fcurves if fc.group}
    fact(case, "bones_keyed", "%d/%d" % (len(keyed & {b.name for b in arm.data.bones}), len(arm.data.bones)))
    first, last = (int(round(f)) for f in new.frame_range)
    fact(case, "frames", last - first + 1)
    fact(case, "seconds_total", "%.3f" % total)
    import stylus_blender
    fact(case, "seconds_server", "%.3f" % stylus_blender.last_restyle["server_s"])
    return new, first


reference = import_bvh_file(cli_out)
ref_first = int(round(reference.animation_data.action.frame_range[0]))
ref_frames = int(round(reference.animation_data.action.frame_range[1])) - ref_first + 1

# A BVH import.
arm = import_bvh_file(rig)
new, first = restyle("bvh", arm)
compare("bvh", arm, reference, first, ref_first, ref_frames)

# The FBX and the glTF Blender wrote from the same rig, imported: against
# the CLI's transfer of the same file (as Blender and assimp read it).
import numpy  # noqa: E402
if not hasattr(numpy, "bool"):  # Debian's Blender 3.4 glTF importer on numpy 1.24
    numpy.bool = bool
for case, path, reference_path in (("fbx", rig_fbx, cli_fbx_out), ("gltf", rig_glb, cli_glb_out)):
    scene_reference = import_bvh_file(reference_path)
    scene_ref_first = int(round(scene_reference.animation_data.action.frame_range[0]))
    before = set(bpy.data.objects)
    if case == "fbx":
        # Blender's "_end" leaf bones become the leaf bones' tails, as the
        # CLI's reader makes them End Sites.
        bpy.ops.import_scene.fbx(filepath=path, ignore_leaf_bones=True)
    else:
        # Keyed at the scene's rate, which the BVH imports set to the rig's.
        bpy.ops.import_scene.gltf(filepath=path)
    imported = next(o for o in bpy.data.objects if o not in before and o.type == "ARMATURE")
    new, first = restyle(case, imported)
    compare(case, imported, scene_reference, first, scene_ref_first, ref_frames)

# Errors are reported, not raised: a style file that does not exist.
bpy.context.scene.stylus.style_file = os.path.join(work, "missing.bvh")
try:
    bpy.ops.stylus.restyle()
    fact("error", "reported", 0)
except RuntimeError as e:
    fact("error", "reported", int("missing.bvh" in str(e)))
report.close()
