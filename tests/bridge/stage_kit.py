"""What the stage's tests and bench share: pass/fail lines, free ports, a real
stylus-server, and the sample walk as Unity humanoid bones (VMC).

Import after putting this folder on sys.path; `use_client(src, build)` makes
the Python client (and its generated protobuf modules) importable.
"""
import math
import os
import socket
import subprocess
import sys
import time


class Checks:
    """Prints "ok" or "FAIL" per check and exits non-zero at the end if any failed."""

    def __init__(self):
        self.failures = []

    def __call__(self, name, ok, detail=""):
        print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + str(detail)))
        if not ok:
            self.failures.append(name)

    def finish(self):
        if self.failures:
            print("%d FAILED: %s" % (len(self.failures), ", ".join(self.failures)))
            sys.exit(1)
        print("all passed")


def use_client(src, build):
    sys.path.insert(0, os.path.join(src, "client", "python"))
    sys.path.insert(0, os.path.join(build, "proto", "python"))


def build_dir_of(binary):
    """The build folder of a binary two levels down (build/bridge/stylus-bridge)."""
    return os.path.dirname(os.path.dirname(os.path.abspath(binary)))


def free_port(kind):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def start_server(server_bin, src, work, port, log=True):
    """stylus-server on the repository's models at localhost:PORT, once it listens."""
    port_file = os.path.join(work, "port")
    if os.path.exists(port_file):
        os.remove(port_file)
    out = open(os.path.join(work, "server.log"), "a") if log else subprocess.DEVNULL
    p = subprocess.Popen([server_bin, "--models", os.path.join(src, "models"), "--listen",
                          "localhost:%d" % port, "--port-file", port_file], stdout=out, stderr=out)
    for _ in range(600):
        if os.path.exists(port_file) and open(port_file).read().strip():
            return p
        time.sleep(0.05)
    raise SystemExit("the server did not start; see " + work + "/server.log")


# The sample rig's bones (samples/walk_normal.bvh, Bandai's) by their Unity
# HumanBodyBones names.
UNITY = {"Hips": "Hips", "Spine": "Spine", "Chest": "Chest", "Neck": "Neck", "Head": "Head"}
for _part in ("Shoulder", "UpperArm", "LowerArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "Toes"):
    UNITY[_part + "_L"], UNITY[_part + "_R"] = "Left" + _part, "Right" + _part


def unity_bones(clip, row, frame_pose):
    """{unity bone: ((x, y, z), (qx, qy, qz, qw))} of one frame in Unity's
    left-handed axes (x mirrored), in metres."""
    translations, rotations = frame_pose(clip, row)
    bones = {}
    for i, j in enumerate(clip.joints):
        if j.name not in UNITY:
            continue
        x, y, z = (v * 0.01 for v in translations[i])
        w, qx, qy, qz = rotations[i]
        bones[UNITY[j.name]] = ((-x, y, z), (qx, -qy, -qz, w))
    return bones


def quat_angle(q1, q2):
    """The angle (radians) between two unit quaternions, from their difference
    (2 acos of their dot product loses 1e-4 rad to float32 rounding near 0)."""
    s = 1.0 if sum(a * b for a, b in zip(q1, q2)) >= 0 else -1.0
    minus = math.sqrt(sum((a - s * b) ** 2 for a, b in zip(q1, q2)))
    plus = math.sqrt(sum((a + s * b) ** 2 for a, b in zip(q1, q2)))
    return 2 * math.atan2(minus, plus)
