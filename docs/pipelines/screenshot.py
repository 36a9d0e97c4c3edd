"""Takes docs/pipelines/addon_panel.png: Blender with the Stylus add-on's
panel open on a restyled armature. Needs a display (it runs Blender's UI):

  blender -b --factory-startup --python-expr \
      "import bpy; bpy.ops.wm.save_as_mainfile(filepath='/tmp/empty.blend')"
  xvfb-run -s "-screen 0 1600x1000x24" blender --factory-startup /tmp/empty.blend \
      --python docs/pipelines/screenshot.py -- ADDON.zip RIG.bvh STYLE.bvh SERVER OUT.png

(A file on the command line keeps Blender's splash screen away.)

Leaves Blender when the screenshot is written.
"""
import builtins
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
addon, rig, style, server, out = argv
import io_anim_bvh.import_bvh as import_bvh  # Debian's Blender 3.4: 'rU' on Python 3.11
import_bvh.open = lambda p, m="r", *a, **k: builtins.open(p, m.replace("U", ""), *a, **k)

bpy.ops.preferences.addon_install(filepath=addon, overwrite=True)
bpy.ops.preferences.addon_enable(module="stylus_blender")
# Blender 3.4 cannot switch the sidebar's tab from Python, and it opens on
# "Item": the screenshot shows the panel there (users find it under "Stylus").
import stylus_blender  # noqa: E402
bpy.utils.unregister_class(stylus_blender.STYLUS_PT_panel)
stylus_blender.STYLUS_PT_panel.bl_category = "Item"
bpy.utils.register_class(stylus_blender.STYLUS_PT_panel)
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
bpy.ops.import_anim.bvh(filepath=rig, update_scene_fps=True, update_scene_duration=True)
arm = bpy.context.selected_objects[0]
bpy.context.view_layer.objects.active = arm
s = bpy.context.scene.stylus
s.server, s.style_file, s.postprocess = server, style, "full"
bpy.ops.stylus.restyle()
bpy.context.scene.frame_set(30)


def shoot():
    try:
        frame_views()
    finally:
        bpy.app.timers.register(save, first_interval=1.0)


def frame_views():
    for area in bpy.context.screen.areas:
        if area.type == "VIEW_3D":
            space = area.spaces.active
            space.show_region_ui = True
            region = next(r for r in area.regions if r.type == "WINDOW")
            with bpy.context.temp_override(area=area, region=region):
                bpy.ops.view3d.view_all(center=True)


def save():
    try:
        bpy.ops.screen.screenshot(filepath=out)
    finally:
        bpy.ops.wm.quit_blender()


bpy.app.timers.register(shoot, first_interval=1.0)
