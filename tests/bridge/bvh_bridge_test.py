#!/usr/bin/python3
"""stylus-bridge on BVH broadcast, as Axis Neuron / Axis Studio send it and
engines' Neuron plug-ins receive it. Nobody here wrote a sender of that
format before this test: it replays one from the format's description
(docs/stage.md "BVH broadcast"), independent of the bridge's code.

A capture side (a TCP server, as the capture software is) sends a walk
(samples/walk_normal.bvh, the skeleton file the bridge is given) for two
avatars in the text form at 60 Hz; an engine connects to the bridge's
--bvh-out and reads the text form back; a third avatar comes in the binary
form over UDP and goes out binary to a UDP receiver. Checks: every frame
reaches the engine, in order, stylized; the server killed, the performer
passes through unchanged and the engine misses nothing; the server back,
styled frames within 2 s; the capture software restarted, the bridge
connects again; bad frames are counted, never passed on.

Usage: bvh_bridge_test.py STYLUS_SERVER STYLUS_BRIDGE SOURCE_DIR WORK_DIR
"""
import math
import os
import shutil
import socket
import struct
import subprocess
import sys
import threading
import time

server_bin, bridge_bin, src, work = sys.argv[1:5]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stage_kit import Checks, build_dir_of, free_port, quat_angle, use_client  # noqa: E402
from stage_kit import start_server as stage_start_server  # noqa: E402
use_client(src, build_dir_of(bridge_bin))
from stylus_client.bvh import frame_pose, read_bvh  # noqa: E402

shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
check = Checks()
FPS = 60.0


skeleton_file = os.path.join(src, "samples", "walk_normal.bvh")
clip = read_bvh(skeleton_file)
rows = clip.frames

# The command line: help, and clear errors before anything starts.
style = os.path.join(src, "samples", "walk_old.bvh")
for args, want in (
        (["--bvh-in", "localhost:7001", "--bvh-out", "0", "--style", style], "--bvh-skeleton FILE is required"),
        (["--bvh-in", "localhost:7001", "--bvh-skeleton", skeleton_file, "--style", style],
         "needs --bvh-out PORT or --bvh-out-udp HOST:PORT"),
        (["--bvh-in", "nowhere", "--bvh-skeleton", skeleton_file, "--bvh-out", "0", "--style", style],
         "--bvh-in nowhere: expected HOST:PORT"),
        (["--bvh-in-udp", "0", "--bvh-skeleton", os.path.join(work, "none.bvh"), "--bvh-out", "0",
          "--style", style], "none.bvh")):
    done = subprocess.run([bridge_bin] + args, capture_output=True, text=True, timeout=30)
    check("stylus-bridge %s -> %s" % (" ".join(args[:2]), want),
          done.returncode == 2 and want in done.stderr, (done.returncode, done.stderr[-300:]))
done = subprocess.run([bridge_bin, "--help"], capture_output=True, text=True, timeout=30)
check("--help tells the BVH broadcast options", done.returncode == 0 and "--bvh-in" in done.stdout
      and "--bvh-skeleton" in done.stdout and "--bvh-out-udp" in done.stdout, done.stdout[-300:])


def text_frame(index, name, values):
    return ("%d %s %s ||\n" % (index, name, " ".join("%.5f" % v for v in values))).encode()


def binary_frame(index, name, frame_index, values):
    """64-byte header (little-endian): 0xDDFF, version, count, with displacement,
    with reference, avatar index, name (32 bytes), frame index, 3 reserved,
    0xEEFF; then the values as float32."""
    header = struct.pack("<H4BHBBI32sIIIIH", 0xDDFF, 0, 0, 0, 1, len(values), 1, 0, index,
                         name.encode(), frame_index, 0, 0, 0, 0xEEFF)
    assert len(header) == 64
    return header + struct.pack("<%df" % len(values), *values)


class Capture:
    """The capture software's side: a TCP server the bridge connects to."""

    def __init__(self, port):
        self.port = port
        self.conn = None
        self.listener = None
        self.open()

    def open(self):
        self.listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind(("127.0.0.1", self.port))
        self.listener.listen(1)
        self.listener.settimeout(10)
        self.conn = None

    def accept(self):
        self.conn, _ = self.listener.accept()
        self.conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def restart(self):
        self.conn.close()
        self.listener.close()
        time.sleep(0.2)
        self.open()
        self.accept()


class Engine:
    """An engine's Neuron receiver: connects to the bridge, frames by avatar."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.lock = threading.Lock()
        self.frames = {}  # avatar name -> [values]
        self.running = True
        threading.Thread(target=self.loop, daemon=True).start()

    def loop(self):
        buffer = b""
        while self.running:
            try:
                data = self.sock.recv(65536)
            except socket.timeout:
                continue
            if not data:
                return
            buffer += data
            *done, buffer = buffer.split(b"||")
            for text in done:
                tokens = text.split()
                with self.lock:
                    self.frames.setdefault(tokens[1].decode(), []).append([float(t) for t in tokens[2:]])

    def get(self, name):
        with self.lock:
            return list(self.frames.get(name, []))


def connect_engine(port):
    """An Engine on the bridge's --bvh-out once it listens (None after 10 s)."""
    for _ in range(100):
        try:
            return Engine(port)
        except OSError:
            time.sleep(0.1)
    return None


class BinaryEngine:
    """A receiver of the binary form on UDP."""

    def __init__(self, port):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", port))
        self.sock.settimeout(0.1)
        self.frames = []
        self.running = True
        threading.Thread(target=self.loop, daemon=True).start()

    def loop(self):
        while self.running:
            try:
                d = self.sock.recv(65536)
            except socket.timeout:
                continue
            token, count = struct.unpack_from("<H", d, 0)[0], struct.unpack_from("<H", d, 6)[0]
            name = d[14:46].split(b"\0")[0].decode()
            frame_index = struct.unpack_from("<I", d, 46)[0]
            end = struct.unpack_from("<H", d, 62)[0]
            values = list(struct.unpack_from("<%df" % count, d, 64))
            self.frames.append((token, end, name, frame_index, values))


def start_server(port):
    return stage_start_server(server_bin, src, work, port)


def rotations(row):
    return frame_pose(clip, row)[1]


def difference(sent, got):
    """Mean angle (degrees) between two rows' joint rotations."""
    a, b = rotations(sent), rotations(got)
    angles = [quat_angle(p, q) for p, q in zip(a, b)]
    return math.degrees(sum(angles) / len(angles))


grpc_port, capture_port, out_port = (free_port(socket.SOCK_STREAM) for _ in range(3))
udp_in, udp_out, vmc_in = (free_port(socket.SOCK_DGRAM) for _ in range(3))
server = start_server(grpc_port)
capture = Capture(capture_port)
binary_engine = BinaryEngine(udp_out)
bridge_log = open(os.path.join(work, "bridge.log"), "w")
bridge = subprocess.Popen([bridge_bin, "--server", "localhost:%d" % grpc_port, "--vmc-in", str(vmc_in),
                           "--bvh-in", "localhost:%d" % capture_port, "--bvh-in-udp", str(udp_in),
                           "--bvh-skeleton", skeleton_file, "--bvh-out", str(out_port),
                           "--bvh-out-udp", "127.0.0.1:%d" % udp_out, "--style", style,
                           "--fps", str(int(FPS)), "--stats", "1"],
                          stdout=bridge_log, stderr=subprocess.STDOUT)
sent = {"Avatar00": [], "Avatar01": []}
try:
    capture.accept()
    engine = connect_engine(out_port)
    check("an engine connects to --bvh-out", engine is not None)
    time.sleep(0.3)

    def play(count, avatars=("Avatar00",)):
        start = time.monotonic()
        for k in range(count):
            for i, name in enumerate(avatars):
                row = rows[len(sent[name]) % len(rows)]
                capture.conn.sendall(text_frame(i, name, row))
                sent[name].append(row)
            time.sleep(max(0.0, start + (k + 1) / FPS - time.monotonic()))

    def settle():
        time.sleep(0.4)

    play(240, ("Avatar00", "Avatar01"))  # 4 s, two avatars on one connection.
    settle()
    got = engine.get("Avatar00")
    check("the engine gets Avatar00's frames (all but the stream's look-ahead, <= 4)",
          len(sent["Avatar00"]) - 4 <= len(got) <= len(sent["Avatar00"]), (len(got), len(sent["Avatar00"])))
    check("each with the skeleton file's channels", all(len(v) == len(rows[0]) for v in got),
          {len(v) for v in got})
    styled = [difference(sent["Avatar00"][t], got[t]) for t in range(30, len(got))]
    mean_styled = sum(styled) / max(1, len(styled))
    check("stylized (mean rotation difference > 2 degrees)", mean_styled > 2, mean_styled)
    got1 = engine.get("Avatar01")
    check("a second avatar on the same connection is its own performer, stylized",
          len(got1) >= len(sent["Avatar01"]) - 4
          and sum(difference(sent["Avatar01"][t], got1[t]) for t in range(30, len(got1))) / (len(got1) - 30) > 2,
          len(got1))

    # A frame that does not fit the skeleton file: counted, not passed on.
    capture.conn.sendall(text_frame(0, "Avatar00", [1.0, 2.0, 3.0]) + b"0 Avatar00 1 x ||\n")

    # The server goes away: the performer passes through, unchanged.
    server.kill()
    server.wait()
    killed_at = len(sent["Avatar00"])
    play(90)
    settle()
    got = engine.get("Avatar00")
    check("server down: every frame reaches the engine, those in flight included",
          len(got) == len(sent["Avatar00"]), (len(got), len(sent["Avatar00"])))
    passed = [max(abs(a - b) for a, b in zip(sent["Avatar00"][t], got[t]))
              for t in range(killed_at + 10, len(got))]
    check("server down: the performer passes through unchanged (< 1e-4)", passed and max(passed) < 1e-4,
          max(passed) if passed else None)

    # It comes back: styled frames resume within 2 s.
    server = start_server(grpc_port)
    back_at = len(sent["Avatar00"])
    play(180)
    settle()
    got = engine.get("Avatar00")
    resumed = next((t for t in range(back_at, len(got)) if difference(sent["Avatar00"][t], got[t]) > 1.0), None)
    check("server back: styled frames resume within 2 s",
          resumed is not None and (resumed - back_at) / FPS <= 2.0,
          None if resumed is None else (resumed - back_at) / FPS)
    if resumed is not None:
        print("     styled again %.2f s after the server was back" % ((resumed - back_at) / FPS))

    # The capture software restarts: the bridge connects again.
    capture.restart()
    before = len(sent["Avatar00"])
    play(120)
    settle()
    got = engine.get("Avatar00")
    check("capture software restarted: its frames reach the engine again",
          len(got) >= len(sent["Avatar00"]) - 4, (len(got), len(sent["Avatar00"]), before))

    # The binary form, over UDP, as a third avatar.
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    start = time.monotonic()
    for k in range(150):
        udp.sendto(binary_frame(2, "Avatar02", k, rows[k % len(rows)]), ("127.0.0.1", udp_in))
        time.sleep(max(0.0, start + (k + 1) / FPS - time.monotonic()))
    udp.sendto(b"not a frame", ("127.0.0.1", udp_in))
    settle()
    out = [f for f in binary_engine.frames if f[2] == "Avatar02"]
    check("binary in, binary out: the frames come back with their header",
          len(out) >= 146 and all(f[0] == 0xDDFF and f[1] == 0xEEFF for f in out)
          and [f[3] for f in out] == list(range(len(out))), (len(out), out[:1]))
    styled_binary = [difference(rows[f[3] % len(rows)], f[4]) for f in out[30:]]
    check("binary: stylized", styled_binary and sum(styled_binary) / len(styled_binary) > 2,
          styled_binary[:3])
    # The sender restarts: its frame index starts again from 0, and is taken.
    start = time.monotonic()
    for k in range(60):
        udp.sendto(binary_frame(2, "Avatar02", k, rows[k % len(rows)]), ("127.0.0.1", udp_in))
        time.sleep(max(0.0, start + (k + 1) / FPS - time.monotonic()))
    settle()
    again = [f for f in binary_engine.frames if f[2] == "Avatar02"][len(out):]
    check("binary: a restarted sender (frame index from 0 again) is taken", len(again) >= 56,
          len(again))
finally:
    bridge.terminate()
    try:
        bridge.wait(timeout=10)
    except subprocess.TimeoutExpired:
        bridge.kill()
    server.terminate()
    server.wait()
# A skeleton whose joint names say nothing (b00, b01, ...): without a joint
# map the server cannot find its legs and the performer passes through;
# with --joint-map it is styled.
ROLES = {"pelvis": "Hips", "spine": "Spine", "chest": "Chest", "neck": "Neck", "head": "Head"}
for side, s_ in (("left", "L"), ("right", "R")):
    for role, joint in (("clavicle", "Shoulder"), ("upper_arm", "UpperArm"), ("forearm", "LowerArm"),
                        ("hand", "Hand"), ("thigh", "UpperLeg"), ("shin", "LowerLeg"), ("foot", "Foot"),
                        ("toe", "Toes")):
        ROLES["%s_%s" % (side, role)] = "%s_%s" % (joint, s_)
renamed = {j.name: "b%02d" % i for i, j in enumerate(clip.joints)}
text = open(skeleton_file).read()
for old_name, new_name in renamed.items():
    text = text.replace("ROOT %s\n" % old_name, "ROOT %s\n" % new_name).replace(
        "JOINT %s\n" % old_name, "JOINT %s\n" % new_name)
anonymous = os.path.join(work, "anonymous.bvh")
open(anonymous, "w").write(text)
joint_map = os.path.join(work, "anonymous.map")
open(joint_map, "w").write("".join("%s = %s\n" % (role, renamed[name]) for role, name in ROLES.items()))


def styled_with(extra):
    """Mean rotation difference (degrees) of 120 text frames through a bridge
    on the anonymous skeleton, with `extra` options."""
    capture_port, out_port = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    cap = Capture(capture_port)
    b = subprocess.Popen([bridge_bin, "--server", "localhost:%d" % grpc_port, "--vmc-in",
                          str(free_port(socket.SOCK_DGRAM)), "--bvh-in", "localhost:%d" % capture_port,
                          "--bvh-skeleton", anonymous, "--bvh-out", str(out_port), "--style", style] + extra,
                         stdout=open(os.path.join(work, "anonymous.log"), "a"), stderr=subprocess.STDOUT)
    try:
        cap.accept()
        eng = connect_engine(out_port)
        time.sleep(0.3)
        start = time.monotonic()
        for k in range(120):
            cap.conn.sendall(text_frame(0, "Avatar00", rows[k % len(rows)]))
            time.sleep(max(0.0, start + (k + 1) / FPS - time.monotonic()))
        time.sleep(0.4)
        got = eng.get("Avatar00") if eng else []
        return sum(difference(rows[t % len(rows)], got[t]) for t in range(30, len(got))) / max(1, len(got) - 30)
    finally:
        b.terminate()
        b.wait(timeout=10)
        cap.conn.close()
        cap.listener.close()


server = start_server(grpc_port)
try:
    without, with_map = styled_with([]), styled_with(["--joint-map", joint_map])
finally:
    server.terminate()
    server.wait()
print("     anonymous joint names: %.2f degrees from the performer without a joint map, %.2f with one"
      % (without, with_map))
check("a skeleton whose names don't say is styled with --joint-map (and not without)",
      without < 0.01 and with_map > 2, (without, with_map))
log = open(os.path.join(work, "bridge.log")).read()
stats = [line for line in log.splitlines() if line.startswith("performers")]
print("     " + (stats[-1] if stats else "(no counters printed)"))
check("three performers, the failure and the reconnect counted", stats and " performers 3 " in " " + stats[-1]
      and " reconnects 0 " not in stats[-1] and " stream_failures 0 " not in stats[-1], stats[-1] if stats else log[-500:])
check("bad frames counted (malformed >= 3)", stats and int(stats[-1].split(" malformed ")[1].split()[0]) >= 3,
      stats[-1] if stats else None)
check("the bad frame's error names both counts", "a frame of 3 values, but the skeleton file has" in log, log[-500:])
check("the bridge stops on SIGTERM", bridge.returncode == 0, bridge.returncode)
check.finish()
