"""An armature's action to a Stylus clip and back.

The clip is the one Blender's BVH exporter would write: Y up, each joint's
frame world-aligned at rest (rotations are relative to the rest pose, so a
zero pose is the armature's rest pose), offsets from bone head to bone head,
the root's position in armature space; leaf bones' tails are End Sites. The
action's F-curves are evaluated directly (no scene update per frame), so the
motion is the action's own: constraints and drivers are not baked (bake the
action first, Pose > Animation > Bake Action, if they matter).
"""
from __future__ import annotations

from typing import Dict, List, Sequence, Tuple

from mathutils import Euler, Matrix, Quaternion, Vector

from stylus_client.bvh import Clip, Joint, frame_pose, pose_row

# Blender's armature space (Z up, -Y forward) to the clip's (Y up, +Z forward)
# and back, as Blender's BVH importer and exporter turn them.
TO_Y_UP = Matrix(((1, 0, 0), (0, 0, 1), (0, -1, 0)))
TO_Z_UP = TO_Y_UP.transposed()
ROTATION_CHANNELS = ["Zrotation", "Xrotation", "Yrotation"]
POSITION_CHANNELS = ["Xposition", "Yposition", "Zposition"]


def _ordered_bones(armature) -> List:
    """Bones depth-first, each parent before its children (one root)."""
    roots = [b for b in armature.data.bones if b.parent is None]
    if len(roots) != 1:
        raise ValueError("the armature has %d root bones; Stylus needs one skeleton with one root "
                         "(parent the others to it)" % len(roots))
    order, stack = [], [roots[0]]
    while stack:
        bone = stack.pop()
        order.append(bone)
        stack.extend(reversed(bone.children))
    return order


def _to_y_up(v: Vector) -> Tuple[float, float, float]:
    w = TO_Y_UP @ v
    return (w.x, w.y, w.z)


def _rest(bone) -> Tuple[Matrix, Vector]:
    """A bone's rest rotation and head in armature space."""
    return bone.matrix_local.to_3x3().normalized(), bone.matrix_local.to_translation()


def skeleton_of(armature) -> Tuple[List, List[Joint]]:
    """The armature's bones (in clip order) and the clip's joints."""
    bones = _ordered_bones(armature)
    index = {b.name: i for i, b in enumerate(bones)}
    joints = []
    for bone in bones:
        head = bone.head_local
        if bone.parent is None:
            offset, parent = _to_y_up(head), -1
            channels = POSITION_CHANNELS + ROTATION_CHANNELS
        else:
            offset, parent = _to_y_up(head - bone.parent.head_local), index[bone.parent.name]
            channels = list(ROTATION_CHANNELS)
        end_sites = [] if bone.children else [_to_y_up(bone.tail_local - head)]
        joints.append(Joint(bone.name, parent, offset, channels, end_sites))
    return bones, joints


def _curves(action, bone_name: str) -> Dict[str, List]:
    prefix = 'pose.bones["%s"].' % bone_name.replace('"', '\\"')
    found: Dict[str, List] = {}
    for fc in action.fcurves:
        if fc.data_path.startswith(prefix):
            prop = fc.data_path[len(prefix):]
            found.setdefault(prop, [None] * 4)
            if fc.array_index < 4:
                found[prop][fc.array_index] = fc
    return found


def _basis(pose_bone, curves: Dict[str, List], frame: float) -> Matrix:
    """The bone's local pose matrix (matrix_basis) at `frame` from the action."""
    def value(prop, i, default):
        fc = curves.get(prop, [None] * 4)[i]
        return fc.evaluate(frame) if fc is not None else default

    location = Vector([value("location", i, pose_bone.location[i]) for i in range(3)])
    scale = Vector([value("scale", i, pose_bone.scale[i]) for i in range(3)])
    mode = pose_bone.rotation_mode
    if mode == "QUATERNION":
        q = Quaternion([value("rotation_quaternion", i, pose_bone.rotation_quaternion[i])
                        for i in range(4)])
        rotation = q.normalized().to_matrix()
    elif mode == "AXIS_ANGLE":
        aa = [value("rotation_axis_angle", i, pose_bone.rotation_axis_angle[i]) for i in range(4)]
        rotation = Quaternion(Vector(aa[1:]), aa[0]).to_matrix()
    else:
        rotation = Euler([value("rotation_euler", i, pose_bone.rotation_euler[i])
                          for i in range(3)], mode).to_matrix()
    return Matrix.Translation(location) @ rotation.to_4x4() @ Matrix.Diagonal(scale.to_4d())


def clip_from_action(armature, action, first: int, last: int, fps: float) -> Clip:
    """Frames first..last of `action` on `armature` as a clip at `fps`."""
    bones, joints = skeleton_of(armature)
    clip = Clip(joints, 1.0 / fps)
    pose_bones = [armature.pose.bones[b.name] for b in bones]
    curves = [_curves(action, b.name) for b in bones]
    rests = [b.matrix_local for b in bones]
    rest_rot = [_rest(b)[0] for b in bones]
    parent = [j.parent for j in joints]
    previous = None
    for frame in range(first, last + 1):
        pose: List[Matrix] = []
        aligned: List[Matrix] = []
        translations, rotations = [], []
        for i, pb in enumerate(pose_bones):
            basis = _basis(pb, curves[i], frame)
            if parent[i] < 0:
                m = rests[i] @ basis
            else:
                m = pose[parent[i]] @ (rests[parent[i]].inverted() @ rests[i]) @ basis
            pose.append(m)
            a = TO_Y_UP @ (m.to_3x3().normalized() @ rest_rot[i].transposed()) @ TO_Z_UP
            aligned.append(a)
            local = a if parent[i] < 0 else aligned[parent[i]].transposed() @ a
            q = local.to_quaternion()
            rotations.append((q.w, q.x, q.y, q.z))
            translations.append(_to_y_up(m.to_translation()) if parent[i] < 0 else joints[i].offset)
        previous = pose_row(clip, translations, rotations, previous)
        clip.frames.append(previous)
    return clip


def write_action(armature, clip: Clip, name: str, first: int):
    """A new action `name` on `armature` from `clip` (on the armature's own
    skeleton), keyed from frame `first`, one key per frame; each bone keyed
    in its own rotation mode, the root's location too. Returns the action."""
    bones, joints = skeleton_of(armature)
    if [j.name for j in clip.joints] != [j.name for j in joints]:
        raise ValueError("the server returned another skeleton than the armature's")
    pose_bones = [armature.pose.bones[b.name] for b in bones]
    rests = [b.matrix_local for b in bones]
    rest_rot = [_rest(b)[0] for b in bones]
    heads = [b.head_local for b in bones]
    parent = [j.parent for j in joints]
    n = len(bones)
    keys: List[Dict[str, List[float]]] = [dict() for _ in range(n)]
    previous_q: List = [None] * n
    previous_e: List = [None] * n
    for f, row in enumerate(clip.frames):
        translations, rotations = frame_pose(clip, row)
        aligned: List[Matrix] = []
        pose: List[Matrix] = []
        for i in range(n):
            local = Quaternion(rotations[i]).to_matrix()
            a_y = local if parent[i] < 0 else aligned[parent[i]] @ local
            aligned.append(a_y)
            a = TO_Z_UP @ a_y @ TO_Y_UP
            if parent[i] < 0:
                head = TO_Z_UP @ Vector(translations[i])
            else:
                p = parent[i]
                head = pose[p].to_translation() + (TO_Z_UP @ aligned[p] @ TO_Y_UP) @ (heads[i] - heads[p])
            m = Matrix.Translation(head) @ (a @ rest_rot[i]).to_4x4()
            pose.append(m)
            if parent[i] < 0:
                basis = rests[i].inverted() @ m
            else:
                basis = (rests[parent[i]].inverted() @ rests[i]).inverted() @ (pose[parent[i]].inverted() @ m)
            loc, q, _ = basis.decompose()
            k = keys[i]
            mode = pose_bones[i].rotation_mode
            if mode in ("QUATERNION", "AXIS_ANGLE"):
                if previous_q[i] is not None:
                    q.make_compatible(previous_q[i])
                previous_q[i] = q
                k.setdefault("rotation_quaternion", []).append(tuple(q))
            else:
                e = q.to_euler(mode, previous_e[i]) if previous_e[i] is not None else q.to_euler(mode)
                previous_e[i] = e
                k.setdefault("rotation_euler", []).append(tuple(e))
            k.setdefault("location", []).append(tuple(loc))
    # Locations are keyed on the root, and on any other bone the output moves
    # away from its rest head.
    for i in range(1, n):
        if max(Vector(v).length for v in keys[i]["location"]) <= 1e-5 * max(bones[i].length, 1e-6):
            del keys[i]["location"]
    action = bpy_new_action(name)
    for i, bone in enumerate(bones):
        if pose_bones[i].rotation_mode == "AXIS_ANGLE":
            pose_bones[i].rotation_mode = "QUATERNION"
        # What the new action does not key holds the rest value, not what the
        # previous action left there (FBX imports key every bone's location
        # and scale).
        if "location" not in keys[i]:
            pose_bones[i].location = (0.0, 0.0, 0.0)
        pose_bones[i].scale = (1.0, 1.0, 1.0)
        for prop, values in keys[i].items():
            path = 'pose.bones["%s"].%s' % (bone.name.replace('"', '\\"'), prop)
            for axis in range(len(values[0])):
                fc = action.fcurves.new(path, index=axis, action_group=bone.name)
                fc.keyframe_points.add(len(values))
                co = []
                for f, v in enumerate(values):
                    co += [first + f, v[axis]]
                fc.keyframe_points.foreach_set("co", co)
                for kp in fc.keyframe_points:
                    kp.interpolation = "LINEAR"
                fc.update()
    return action


def bpy_new_action(name: str):
    import bpy
    return bpy.data.actions.new(name)
