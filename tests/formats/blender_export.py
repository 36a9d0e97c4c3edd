"""Blender (headless) writes the scene files the format tests read.

blender -b --factory-startup --python blender_export.py -- IN.bvh OUT_DIR [--still]

Imports IN.bvh as Blender's BVH importer does and exports, from the same
armature, OUT_DIR/<stem>.fbx, <stem>.glb, <stem>.gltf and <stem>.dae with the
clip's frames, and <stem>_still.glb without animation. With --two, also
<stem>_two.fbx holding two actions (the clip, and "aside": the clip with its
root bone moved one unit along its local x).
"""
import builtins
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
src, out_dir = argv[0], argv[1]
stem = os.path.splitext(os.path.basename(src))[0]

# Debian's Blender 3.4 runs on Python 3.11, where open(..., 'rU') is an error,
# and its BVH importer still opens files so: give that module an open() that
# drops the 'U'.
import io_anim_bvh.import_bvh as import_bvh  # noqa: E402
import_bvh.open = lambda path, mode="r", *a, **k: builtins.open(path, mode.replace("U", ""), *a, **k)

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_anim.bvh(filepath=src, update_scene_fps=True, update_scene_duration=True)
arm = bpy.context.selected_objects[0]
action = arm.animation_data.action
first, last = (int(round(f)) for f in action.frame_range)
scene = bpy.context.scene
scene.frame_start, scene.frame_end = first, last
scene.frame_set(first)

fbx = dict(add_leaf_bones=True, bake_anim=True, bake_anim_use_all_actions=False,
           bake_anim_use_nla_strips=False, bake_anim_simplify_factor=0.0)
bpy.ops.export_scene.fbx(filepath=os.path.join(out_dir, stem + ".fbx"), **fbx)
gltf = dict(export_animations=True, export_force_sampling=True, export_frame_range=True)
bpy.ops.export_scene.gltf(filepath=os.path.join(out_dir, stem + ".glb"), export_format="GLB", **gltf)
bpy.ops.export_scene.gltf(filepath=os.path.join(out_dir, stem + ".gltf"), export_format="GLTF_SEPARATE",
                          **gltf)
bpy.ops.wm.collada_export(filepath=os.path.join(out_dir, stem + ".dae"), include_animations=True,
                          sampling_rate=1, keep_smooth_curves=False,
                          export_animation_type_selection="sample")
bpy.ops.export_scene.gltf(filepath=os.path.join(out_dir, stem + "_still.glb"), export_format="GLB",
                          export_animations=False)
if "--mesh" in argv:
    # A box skinned to the first bone (weights by vertex group, as Blender's
    # own skinning writes them): a character whose mesh a glTF must keep.
    bpy.ops.object.select_all(action="DESELECT")
    bpy.ops.mesh.primitive_cube_add(size=0.2 * max(arm.dimensions))
    box = bpy.context.active_object
    group = box.vertex_groups.new(name=arm.data.bones[0].name)
    group.add([v.index for v in box.data.vertices], 1.0, "REPLACE")
    box.modifiers.new("Armature", "ARMATURE").object = arm
    box.parent = arm
    bpy.ops.export_scene.gltf(filepath=os.path.join(out_dir, stem + "_mesh.glb"), export_format="GLB", **gltf)
if "--two" in argv:
    # The same clip, a unit to the side: the root bone's x location + 1.
    second = action.copy()
    second.name = "aside"
    root = arm.data.bones[0].name
    for curve in second.fcurves:
        if curve.data_path == 'pose.bones["%s"].location' % root and curve.array_index == 0:
            for key in curve.keyframe_points:
                key.co.y += 1.0
                key.handle_left.y += 1.0
                key.handle_right.y += 1.0
        curve.update()
    arm.animation_data.action = action
    track = arm.animation_data.nla_tracks.new()
    track.strips.new("aside", first, second)
    bpy.ops.export_scene.fbx(filepath=os.path.join(out_dir, stem + "_two.fbx"), add_leaf_bones=False,
                             bake_anim=True, bake_anim_use_all_actions=True,
                             bake_anim_use_nla_strips=False, bake_anim_simplify_factor=0.0)
print("exported", stem, len(arm.data.bones), "bones", first, last)
