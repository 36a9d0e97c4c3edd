"""Stylus inside Blender: restyle an armature's action through a Stylus server.

The panel (3D View > Sidebar > Stylus, with an armature active) holds the
server's address and token, the model, the style (a clip file or a style
saved on the server), strength, post-processing and timing. Restyle sends
the active action and creates a new action "<action>.<style>" on the same
armature, leaving the original (kept with a fake user). Scripts call
``bpy.ops.stylus.restyle()`` with the same settings in ``scene.stylus``.
"""
import os
import sys
import threading
import time

import bpy
from bpy.props import EnumProperty, FloatProperty, PointerProperty, StringProperty

bl_info = {
    "name": "Stylus motion style transfer",
    "author": "Stylus",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "3D View > Sidebar > Stylus",
    "description": "Restyle an armature's action through a Stylus server",
    "category": "Animation",
}

# The Python client and its generated API modules travel inside the add-on.
_VENDOR = os.path.join(os.path.dirname(__file__), "vendor")
if _VENDOR not in sys.path:
    sys.path.insert(0, _VENDOR)

_saved_styles = []  # (name, name, "") items from the last refresh.
# What the last restyle did, for scripts: action, frames, seconds in the
# server call and in all (reading the action, the call, writing keys).
last_restyle = {}


def _saved_style_items(self, context):
    return _saved_styles or [("", "(refresh the list)", "")]


class StylusSettings(bpy.types.PropertyGroup):
    server: StringProperty(name="Server", default=os.environ.get("STYLUS_SERVER", "localhost:50051"),
                           description="host:port of the Stylus server")
    token: StringProperty(name="Token", subtype="PASSWORD", default=os.environ.get("STYLUS_TOKEN", ""),
                          description="The server's access token, if it asks for one")
    tls_ca: StringProperty(name="TLS CA", subtype="FILE_PATH",
                           description="For a TLS server: its CA's PEM file, or 'system'")
    model: StringProperty(name="Model", description="NAME or NAME/VERSION; empty: the server's default")
    style_source: EnumProperty(name="Style from", items=[
        ("FILE", "Clip file", "A style clip: .bvh, .fbx, .gltf, .glb or .dae"),
        ("SAVED", "Saved style", "A style saved on the server for this model")])
    style_file: StringProperty(name="Style clip", subtype="FILE_PATH")
    style_name: EnumProperty(name="Saved style", items=_saved_style_items)
    strength: FloatProperty(name="Strength", default=1.0, min=0.0, max=1.0,
                            description="1: the style as the model gives it; below 1, blended "
                                        "with the content's own style (the content's timing)")
    postprocess: EnumProperty(name="Clean-up", default="default", items=[
        ("default", "Server default", ""), ("none", "None", ""),
        ("feet", "Feet", "Feet locked where planted"),
        ("full", "Full", "Feet, bone lengths, smoothing")])
    timing: EnumProperty(name="Timing", items=[
        ("content", "Content", "Frame for frame the action's timing"),
        ("style", "Style", "The style's pace: the action gets longer or shorter")])


def _client(settings):
    from stylus_client import Client
    return Client(settings.server, token=settings.token or None,
                  tls_ca=bpy.path.abspath(settings.tls_ca) if settings.tls_ca else None)


def _style(settings):
    """The style argument and a label for the new action's name."""
    from stylus_client import read_clip
    if settings.style_source == "SAVED":
        if not settings.style_name:
            raise ValueError("no saved style chosen: press the refresh button to list them")
        return settings.style_name, settings.style_name
    path = bpy.path.abspath(settings.style_file)
    if not settings.style_file or not os.path.isfile(path):
        raise ValueError("choose a style clip file (%s does not exist)" % (path or "none"))
    return read_clip(path), os.path.splitext(os.path.basename(path))[0]


def _armature_and_action(context):
    obj = context.object
    if obj is None or obj.type != "ARMATURE":
        raise ValueError("select an armature")
    action = obj.animation_data.action if obj.animation_data else None
    if action is None:
        raise ValueError("%s has no active action to restyle" % obj.name)
    return obj, action


class _Job:
    """One restyle: the content read on Blender's thread, the call on any."""

    def __init__(self, context):
        from .armature_motion import clip_from_action
        self.began = time.monotonic()
        settings = context.scene.stylus
        self.armature, self.action = _armature_and_action(context)
        self.first, last = (int(round(f)) for f in self.action.frame_range)
        render = context.scene.render
        fps = render.fps / render.fps_base
        self.style, self.label = _style(settings)
        self.content = clip_from_action(self.armature, self.action, self.first, last, fps)
        self.settings = {k: getattr(settings, k) for k in
                         ("server", "token", "tls_ca", "model", "strength", "postprocess", "timing")}
        self.client = _client(settings)
        self.result = None
        self.error = None
        self.seconds = 0.0

    def call(self):
        s = self.settings
        start = time.monotonic()
        try:
            with self.client as c:
                if s["strength"] >= 0.999:
                    self.result = c.transfer(self.content, self.style, model=s["model"],
                                             postprocess=s["postprocess"], timing=s["timing"])
                else:
                    k = s["strength"]
                    self.result = c.interpolate(self.content, [self.style, self.content],
                                                weights=[k, 1.0 - k], model=s["model"],
                                                postprocess=s["postprocess"])
        except Exception as e:  # Reported in Blender, not raised into its event loop.
            self.error = e
        self.seconds = time.monotonic() - start

    def finish(self):
        """The new action on the armature (Blender's thread)."""
        from .armature_motion import write_action
        if self.error is not None:
            raise self.error
        name = "%s.%s" % (self.action.name, self.label)
        new = write_action(self.armature, self.result, name, self.first)
        self.action.use_fake_user = True
        self.armature.animation_data.action = new
        last_restyle.clear()
        last_restyle.update(action=new.name, frames=len(self.result.frames),
                            server_s=self.seconds, total_s=time.monotonic() - self.began)
        return new


class STYLUS_OT_restyle(bpy.types.Operator):
    """Restyle the active armature's action through the Stylus server"""
    bl_idname = "stylus.restyle"
    bl_label = "Restyle"
    bl_options = {"REGISTER", "UNDO"}

    _timer = None
    _thread = None
    _job = None

    def _start(self, context):
        try:
            self._job = _Job(context)
        except Exception as e:
            self.report({"ERROR"}, "Stylus: %s" % e)
            return False
        return True

    def _done(self, context):
        try:
            new = self._job.finish()
        except Exception as e:
            self.report({"ERROR"}, "Stylus: %s" % e)
            return {"CANCELLED"}
        self.report({"INFO"}, "Stylus: %s, %d frames (%.1f s on the server)" %
                    (new.name, len(self._job.result.frames), self._job.seconds))
        return {"FINISHED"}

    def execute(self, context):
        # Scripts and headless runs: one blocking call.
        if not self._start(context):
            return {"CANCELLED"}
        self._job.call()
        return self._done(context)

    def invoke(self, context, event):
        # The UI: the call runs on a thread while the status bar counts.
        if not self._start(context):
            return {"CANCELLED"}
        self._thread = threading.Thread(target=self._job.call, daemon=True)
        self._thread.start()
        self._began = time.monotonic()
        self._timer = context.window_manager.event_timer_add(0.1, window=context.window)
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        if self._thread.is_alive():
            context.workspace.status_text_set("Stylus: restyling %d frames of %s... %.1f s" % (
                len(self._job.content.frames), self._job.action.name, time.monotonic() - self._began))
            return {"RUNNING_MODAL"}
        context.window_manager.event_timer_remove(self._timer)
        context.workspace.status_text_set(None)
        return self._done(context)


class STYLUS_OT_refresh_styles(bpy.types.Operator):
    """List the styles saved on the server for the model"""
    bl_idname = "stylus.refresh_styles"
    bl_label = "Refresh saved styles"

    def execute(self, context):
        settings = context.scene.stylus
        try:
            with _client(settings) as c:
                info = c.model(settings.model)
        except Exception as e:
            self.report({"ERROR"}, "Stylus: %s" % e)
            return {"CANCELLED"}
        _saved_styles[:] = [(n, n, "saved on %s" % info.id) for n in info.saved_styles]
        self.report({"INFO"}, "Stylus: %d saved styles on %s" % (len(_saved_styles), info.id))
        return {"FINISHED"}


class STYLUS_PT_panel(bpy.types.Panel):
    bl_label = "Stylus"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Stylus"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "ARMATURE"

    def draw(self, context):
        s = context.scene.stylus
        col = self.layout.column()
        col.prop(s, "server")
        col.prop(s, "token")
        col.prop(s, "tls_ca")
        col.prop(s, "model")
        col.prop(s, "style_source", expand=True)
        if s.style_source == "FILE":
            col.prop(s, "style_file")
        else:
            row = col.row(align=True)
            row.prop(s, "style_name", text="")
            row.operator("stylus.refresh_styles", text="", icon="FILE_REFRESH")
        col.prop(s, "strength", slider=True)
        col.prop(s, "postprocess")
        col.prop(s, "timing")
        col.operator("stylus.restyle", icon="ARMATURE_DATA")


_classes = (StylusSettings, STYLUS_OT_restyle, STYLUS_OT_refresh_styles, STYLUS_PT_panel)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.stylus = PointerProperty(type=StylusSettings)


def unregister():
    del bpy.types.Scene.stylus
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
