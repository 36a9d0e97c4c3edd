"""Clips to and from the wire types of stylus.v1 (proto/stylus/v1/motion.proto)."""
from __future__ import annotations

from typing import Dict, List, Optional, Sequence

from stylus.v1 import motion_pb2

from .bvh import Clip, Joint, frame_pose, pose_row


def skeleton_to_proto(clip: Clip, joint_map: Optional[Dict[str, str]] = None) -> motion_pb2.Skeleton:
    sk = motion_pb2.Skeleton()
    for j in clip.joints:
        pj = sk.joints.add(name=j.name, parent=j.parent, channels=list(j.channels))
        pj.offset.x, pj.offset.y, pj.offset.z = j.offset
        for e in j.end_sites:
            pe = pj.end_sites.add()
            pe.x, pe.y, pe.z = e
    for role, joint in (joint_map or {}).items():
        sk.joint_map[role] = joint
    return sk


def skeleton_from_proto(sk: motion_pb2.Skeleton) -> List[Joint]:
    return [Joint(j.name, j.parent, (j.offset.x, j.offset.y, j.offset.z), list(j.channels),
                  [(e.x, e.y, e.z) for e in j.end_sites]) for j in sk.joints]


def frame_to_proto(clip: Clip, row: Sequence[float], index: int) -> motion_pb2.Frame:
    translations, rotations = frame_pose(clip, row)
    frame = motion_pb2.Frame(index=index, timestamp=index * clip.frame_time)
    frame.root_position.x, frame.root_position.y, frame.root_position.z = translations[0]
    for i, (j, q) in enumerate(zip(clip.joints, rotations)):
        frame.rotations.add(w=q[0], x=q[1], y=q[2], z=q[3])
        if i > 0 and j.position_channels():
            t = frame.translations.add()
            t.x, t.y, t.z = translations[i]
    return frame


def frame_from_proto(clip: Clip, frame: motion_pb2.Frame,
                     previous: Optional[Sequence[float]] = None) -> List[float]:
    """Channel values of a wire frame on ``clip``'s skeleton, Euler angles
    continuous with ``previous``."""
    translations, rotations, extra = [], [], iter(frame.translations)
    for i, j in enumerate(clip.joints):
        r = frame.rotations[i]
        rotations.append((r.w, r.x, r.y, r.z))
        if i == 0:
            p = frame.root_position
            translations.append((p.x, p.y, p.z))
        elif j.position_channels():
            p = next(extra)
            translations.append((p.x, p.y, p.z))
        else:
            translations.append(j.offset)
    return pose_row(clip, translations, rotations, previous)


def clip_to_proto(clip: Clip, joint_map: Optional[Dict[str, str]] = None) -> motion_pb2.Clip:
    out = motion_pb2.Clip(fps=clip.fps)
    out.skeleton.CopyFrom(skeleton_to_proto(clip, joint_map))
    for f, row in enumerate(clip.frames):
        out.frames.append(frame_to_proto(clip, row, f))
    return out


def clip_from_proto(message: motion_pb2.Clip) -> Clip:
    clip = Clip(skeleton_from_proto(message.skeleton), 1.0 / message.fps)
    previous = None
    for frame in message.frames:
        previous = frame_from_proto(clip, frame, previous)
        clip.frames.append(previous)
    return clip
