#!/usr/bin/python3
"""What the Blender add-on adds to a restyle: a 10 s clip (300 frames at 30 Hz)
on the 55-joint Mixamo rig, restyled five times in headless Blender through a
real stylus-server; prints, per run, the time in all, the server call's, and
the difference (reading the action, converting, writing the keys). Target:
under 2 s added. OPENBLAS_CORETYPE is passed through as the environment has it.

usage: bench/blender_addon_bench.py [BUILD_DIR] [RIG.bvh]
       (defaults: build, ../shared/data/rigs/mixamo_55joints_30fps.bvh)
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

src = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(src, "build"))
rig = sys.argv[2] if len(sys.argv) > 2 else os.path.join(src, "..", "shared", "data", "rigs",
                                                         "mixamo_55joints_30fps.bvh")
RUN = r'''
import builtins, json, sys, time
import bpy
argv = sys.argv[sys.argv.index("--") + 1:]
addon, server, rig, style, out = argv
import io_anim_bvh.import_bvh as ib  # Debian's Blender 3.4: 'rU' on Python 3.11
ib.open = lambda p, m="r", *a, **k: builtins.open(p, m.replace("U", ""), *a, **k)
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.preferences.addon_install(filepath=addon, overwrite=True)
bpy.ops.preferences.addon_enable(module="stylus_blender")
import stylus_blender
bpy.ops.import_anim.bvh(filepath=rig, update_scene_fps=True)
arm = bpy.context.selected_objects[0]
original = arm.animation_data.action
original.use_frame_range, original.frame_start, original.frame_end = True, 1, 300
s = bpy.context.scene.stylus
s.server, s.style_file = server, style
runs = []
for _ in range(5):
    arm.animation_data.action = original
    bpy.ops.stylus.restyle()
    runs.append(dict(stylus_blender.last_restyle))
json.dump(runs, open(out, "w"))
'''

with tempfile.TemporaryDirectory(prefix="stylus-bench-") as work:
    port_file = os.path.join(work, "port")
    server = subprocess.Popen([os.path.join(build, "server", "stylus-server"), "--models",
                               os.path.join(src, "models"), "--listen", "localhost:0", "--port-file",
                               port_file], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(300):
            if os.path.exists(port_file) and open(port_file).read().strip():
                break
            time.sleep(0.1)
        script, out = os.path.join(work, "run.py"), os.path.join(work, "runs.json")
        open(script, "w").write(RUN)
        env = dict(os.environ, BLENDER_USER_SCRIPTS=os.path.join(work, "scripts"))
        subprocess.run(["blender", "-b", "--factory-startup", "--python", script, "--",
                        os.path.join(build, "client", "blender", "stylus_blender.zip"),
                        "localhost:" + open(port_file).read().strip(), rig,
                        os.path.join(src, "samples", "walk_old.bvh"), out],
                       check=True, capture_output=True, env=env)
        import json
        runs = json.load(open(out))
    finally:
        server.terminate()
        server.wait()
print("OPENBLAS_CORETYPE=%s" % os.environ.get("OPENBLAS_CORETYPE", "(not set)"))
print("rig %s, %d frames per restyle" % (os.path.basename(rig), runs[0]["frames"]))
for r in runs:
    print("  in all %.3f s, server call %.3f s, added by the add-on %.3f s" %
          (r["total_s"], r["server_s"], r["total_s"] - r["server_s"]))
added = statistics.median(r["total_s"] - r["server_s"] for r in runs)
print("median added by the add-on: %.3f s per 10 s clip (target < 2 s)" % added)
