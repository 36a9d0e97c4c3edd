"""BVH clips in Python: read, write, and the rotation math the wire needs.

A :class:`Clip` holds what a BVH file holds: a joint hierarchy and, per
frame, one value per channel (positions in the file's units, rotations in
degrees, in each joint's listed channel order). The conventions are the
service's: right-handed, rotations compose in the order the channels are
listed (``Zrotation Xrotation Yrotation`` is Rz * Rx * Ry), quaternions are
(w, x, y, z).
"""
from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]

CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


class BvhError(ValueError):
    """A malformed BVH file: the message says ``source:line: what was expected``."""


@dataclass
class Joint:
    """One joint: name, parent index (-1 for the root), rest offset from the
    parent, channel names (BVH spelling), End Site offsets below it."""

    name: str
    parent: int
    offset: Vec3
    channels: List[str]
    end_sites: List[Vec3] = field(default_factory=list)

    def position_channels(self) -> List[Tuple[int, int]]:
        """(index in channels, axis 0-2) of each position channel."""
        return [(i, CHANNELS.index(c)) for i, c in enumerate(self.channels) if c.endswith("position")]

    def rotation_order(self) -> str:
        """The rotation channels' axes in order, e.g. "ZXY" ("" when none)."""
        return "".join(c[0] for c in self.channels if c.endswith("rotation"))


@dataclass
class Clip:
    """A motion clip: joints in depth-first order, frame time in seconds, and
    ``frames``: one list of channel values per frame."""

    joints: List[Joint]
    frame_time: float = 1.0 / 30
    frames: List[List[float]] = field(default_factory=list)

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    @property
    def num_channels(self) -> int:
        return sum(len(j.channels) for j in self.joints)

    def joint_names(self) -> List[str]:
        return [j.name for j in self.joints]

    def channel_starts(self) -> List[int]:
        starts, at = [], 0
        for j in self.joints:
            starts.append(at)
            at += len(j.channels)
        return starts


# --- rotations ------------------------------------------------------------


def quat_mul(a: Quat, b: Quat) -> Quat:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def euler_to_quat(degrees: Sequence[float], order: str) -> Quat:
    """The rotation of Euler angles (degrees, one per axis of ``order``),
    composed in the order listed."""
    q: Quat = (1.0, 0.0, 0.0, 0.0)
    for angle, axis in zip(degrees, order.upper()):
        half = math.radians(angle) / 2
        v = [0.0, 0.0, 0.0]
        v["XYZ".index(axis)] = math.sin(half)
        q = quat_mul(q, (math.cos(half), v[0], v[1], v[2]))
    return q


def quat_to_matrix(q: Quat) -> List[List[float]]:
    n = math.sqrt(sum(c * c for c in q)) or 1.0
    w, x, y, z = (c / n for c in q)
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def _wrap_near(angle: float, reference: float) -> float:
    return angle + 360.0 * round((reference - angle) / 360.0)


def quat_to_euler(q: Quat, order: str, previous: Optional[Sequence[float]] = None) -> List[float]:
    """Euler angles (degrees, in ``order``) of ``q``: of its two solutions, each
    angle shifted by whole turns, the one nearest ``previous`` (so a clip
    written frame by frame stays continuous)."""
    i, j, k = ("XYZ".index(a) for a in order.upper())
    s = 1.0 if (i, j, k) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1.0
    m = quat_to_matrix(q)
    b = math.asin(max(-1.0, min(1.0, s * m[i][k])))
    if abs(math.cos(b)) > 1e-9:
        a = math.atan2(-s * m[j][k], m[k][k])
        c = math.atan2(-s * m[i][j], m[i][i])
    else:  # Gimbal lock: the third angle is 0.
        a = math.atan2(s * m[k][j], m[j][j])
        c = 0.0
    first = [math.degrees(a), math.degrees(b), math.degrees(c)]
    if previous is None:
        return first
    second = [first[0] + 180.0, 180.0 - first[1], first[2] + 180.0]
    best = None
    for cand in (first, second):
        cand = [_wrap_near(v, p) for v, p in zip(cand, previous)]
        cost = sum((v - p) ** 2 for v, p in zip(cand, previous))
        if best is None or cost < best[0]:
            best = (cost, cand)
    return best[1]


# --- reading and writing --------------------------------------------------


def parse_bvh(text: str, source: str = "<bvh>") -> Clip:
    """Parses BVH text; :class:`BvhError` names ``source`` and the line."""
    tokens: List[Tuple[str, int]] = []
    for number, line in enumerate(text.replace("\r\n", "\n").replace("\r", "\n").split("\n"), 1):
        tokens.extend((t, number) for t in line.split())
    pos = 0

    def fail(what: str) -> BvhError:
        line = tokens[min(pos, len(tokens) - 1)][1] if tokens else 1
        return BvhError("%s:%d: %s" % (source, line, what))

    def take(expected: Optional[str] = None) -> str:
        nonlocal pos
        if pos >= len(tokens):
            raise fail("unexpected end of file" + (" (expected %s)" % expected if expected else ""))
        tok = tokens[pos][0]
        if expected is not None and tok.upper() != expected.upper():
            raise fail("expected %s, got '%s'" % (expected, tok))
        pos += 1
        return tok

    def number(what: str) -> float:
        tok = take()
        try:
            v = float(tok)
        except ValueError:
            raise fail("%s: '%s' is not a number" % (what, tok)) from None
        if not math.isfinite(v):
            raise fail("%s: '%s' is not a finite number" % (what, tok))
        return v

    take("HIERARCHY")
    joints: List[Joint] = []
    stack: List[int] = []
    take("ROOT")
    kind = "ROOT"
    while True:
        if kind in ("ROOT", "JOINT"):
            name = take()
            take("{")
            take("OFFSET")
            offset = (number("offset"), number("offset"), number("offset"))
            take("CHANNELS")
            count_tok = take()
            if not count_tok.isdigit() or int(count_tok) > 6:
                raise fail("channel count must be 0-6, got '%s'" % count_tok)
            channels = []
            for _ in range(int(count_tok)):
                c = take()
                match = [n for n in CHANNELS if n.lower() == c.lower()]
                if not match:
                    raise fail("unknown channel '%s'" % c)
                channels.append(match[0])
            joints.append(Joint(name, stack[-1] if stack else -1, offset, channels))
            stack.append(len(joints) - 1)
        elif kind == "End":
            take("Site")
            take("{")
            take("OFFSET")
            joints[stack[-1]].end_sites.append((number("offset"), number("offset"), number("offset")))
            take("}")
        nxt = take()
        while nxt == "}":
            stack.pop()
            if not stack:
                break
            nxt = take()
        if not stack:
            break
        if nxt == "End":
            kind = "End"
        elif nxt == "JOINT":
            kind = "JOINT"
        else:
            raise fail("expected JOINT, End Site or '}', got '%s'" % nxt)
    take("MOTION")
    take("Frames:")
    frames_tok = take()
    if not frames_tok.isdigit():
        raise fail("frame count must be a whole number, got '%s'" % frames_tok)
    take("Frame")
    take("Time:")
    frame_time = number("frame time")
    if frame_time <= 0:
        raise fail("frame time must be positive")
    clip = Clip(joints, frame_time)
    width = clip.num_channels
    for _ in range(int(frames_tok)):
        clip.frames.append([number("channel value") for _ in range(width)])
    if pos != len(tokens):
        raise fail("more values than %s frames of %d channels" % (frames_tok, width))
    return clip


def read_bvh(path: str) -> Clip:
    """Reads a BVH file (see :func:`parse_bvh`)."""
    with open(path, encoding="utf-8", errors="replace") as f:
        return parse_bvh(f.read(), path)


def _num(v: float) -> str:
    return repr(float(v)) if v != int(v) or abs(v) >= 1e15 else str(int(v))


def format_bvh(clip: Clip) -> str:
    """BVH text of ``clip`` (values in Python's shortest exact form)."""
    out = ["HIERARCHY"]
    children = {i: [] for i in range(len(clip.joints))}
    for i, j in enumerate(clip.joints):
        if j.parent >= 0:
            children[j.parent].append(i)

    def write(i: int, depth: int) -> None:
        j = clip.joints[i]
        pad = "\t" * depth
        out.append("%s%s %s" % (pad, "ROOT" if j.parent < 0 else "JOINT", j.name))
        out.append(pad + "{")
        out.append("%s\tOFFSET %s" % (pad, " ".join(_num(v) for v in j.offset)))
        out.append("%s\tCHANNELS %d%s" % (pad, len(j.channels), "".join(" " + c for c in j.channels)))
        for c in children[i]:
            write(c, depth + 1)
        for e in j.end_sites:
            out.extend([pad + "\tEnd Site", pad + "\t{",
                        "%s\t\tOFFSET %s" % (pad, " ".join(_num(v) for v in e)), pad + "\t}"])
        out.append(pad + "}")

    write(0, 0)
    out.append("MOTION")
    out.append("Frames: %d" % len(clip.frames))
    out.append("Frame Time: %s" % repr(float(clip.frame_time)))
    out.extend(" ".join(_num(v) for v in row) for row in clip.frames)
    return "\n".join(out) + "\n"


def write_bvh(clip: Clip, path: str) -> None:
    """Writes ``clip`` to ``path`` through a temporary file renamed into place."""
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise FileNotFoundError("%s: the folder %s does not exist; create it first" % (path, directory))
    fd, tmp = tempfile.mkstemp(dir=directory, suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(format_bvh(clip))
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


# --- poses ---------------------------------------------------------------


def frame_pose(clip: Clip, row: Sequence[float]) -> Tuple[List[Vec3], List[Quat]]:
    """Local translations and rotations of every joint in one frame row."""
    translations, rotations = [], []
    at = 0
    for j in clip.joints:
        t = list(j.offset)
        euler = []
        for c in j.channels:
            if c.endswith("position"):
                t["XYZ".index(c[0])] = row[at]
            else:
                euler.append(row[at])
            at += 1
        translations.append((t[0], t[1], t[2]))
        rotations.append(euler_to_quat(euler, j.rotation_order()) if euler else (1.0, 0.0, 0.0, 0.0))
    return translations, rotations


def pose_row(clip: Clip, translations: Sequence[Vec3], rotations: Sequence[Quat],
             previous: Optional[Sequence[float]] = None) -> List[float]:
    """The channel values of a pose; Euler angles nearest those of
    ``previous`` (the row before, for continuity)."""
    row: List[float] = []
    starts = clip.channel_starts()
    for index, j in enumerate(clip.joints):
        order = j.rotation_order()
        prev = None
        if previous is not None and order:
            prev = [previous[starts[index] + i] for i, c in enumerate(j.channels)
                    if c.endswith("rotation")]
        euler = quat_to_euler(rotations[index], order, prev) if order else []
        k = 0
        for c in j.channels:
            if c.endswith("position"):
                row.append(translations[index]["XYZ".index(c[0])])
            else:
                row.append(euler[k])
                k += 1
    return row
