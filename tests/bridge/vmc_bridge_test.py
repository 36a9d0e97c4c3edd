#!/usr/bin/python3
"""stylus-bridge against tools nobody here wrote: Python's liblo bindings
(Debian's python3-liblo) play a performer sending VMC and an engine receiving
it, liblo's oscsend changes the strength, and a real stylus-server streams.

A walk (samples/walk_normal.bvh, the Bandai rig named as Unity's humanoid,
in metres) goes out as VMC bundles at 60 Hz. Checks: the engine gets every
frame in order with the performer's bones; the frames are stylized; when the
server is killed the performer passes through, unchanged, and when it comes
back styled frames resume within 2 s; /stylus/strength 0 from oscsend brings
the output back towards the performer's; the counters say so.

Usage: vmc_bridge_test.py STYLUS_SERVER STYLUS_BRIDGE SOURCE_DIR WORK_DIR
"""
import math
import os
import shutil
import socket
import subprocess
import sys
import threading
import time

import liblo

server_bin, bridge_bin, src, work = sys.argv[1:5]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stage_kit import Checks, build_dir_of, free_port, quat_angle, unity_bones, use_client  # noqa: E402
from stage_kit import start_server as stage_start_server  # noqa: E402
use_client(src, build_dir_of(bridge_bin))
from stylus_client.bvh import frame_pose, read_bvh  # noqa: E402

shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
check = Checks()

clip = read_bvh(os.path.join(src, "samples", "walk_normal.bvh"))
frames = [unity_bones(clip, row, frame_pose) for row in clip.frames]

# The command line: help, and clear errors before anything starts.
for args, code, want in (
        (["--help"], 0, "usage: stylus-bridge"),
        (["--style", os.path.join(src, "samples", "walk_old.bvh")], 2, "--vmc-out HOST:PORT is required"),
        (["--vmc-out", "localhost:1", "--style", os.path.join(work, "none.bvh")], 2, "none.bvh"),
        (["--vmc-out", "localhost:1"], 2, "give the style"),
        (["--vmc-out", "nowhere", "--style-name", "x"], 2, "--vmc-out nowhere: expected HOST:PORT"),
        (["--bogus", "1"], 2, "unknown option --bogus")):
    done = subprocess.run([bridge_bin] + args, capture_output=True, text=True, timeout=30)
    check("stylus-bridge %s -> %s" % (" ".join(args), want), done.returncode == code and want in done.stdout + done.stderr,
          (done.returncode, (done.stdout + done.stderr)[-300:]))
FPS = 60.0


class Engine:
    """An engine's VMC receiver: frames by their /VMC/Ext/T, with bone counts."""

    def __init__(self, port):
        self.server = liblo.Server(port)
        self.lock = threading.Lock()
        self.frames = {}  # time -> {bone: (p, q)}
        self.current = {}
        self.ok = 0
        self.server.add_method("/VMC/Ext/Bone/Pos", None, self.bone)
        self.server.add_method("/VMC/Ext/Root/Pos", None, lambda *a: None)
        self.server.add_method("/VMC/Ext/OK", None, self.on_ok)
        self.server.add_method("/VMC/Ext/T", "f", self.on_time)
        self.running = True
        self.thread = threading.Thread(target=self.loop, daemon=True)
        self.thread.start()

    def loop(self):
        while self.running:
            self.server.recv(20)

    def bone(self, path, args):
        self.current[args[0]] = (tuple(args[1:4]), tuple(args[4:8]))

    def on_ok(self, path, args):
        self.ok += 1

    def on_time(self, path, args):
        with self.lock:
            self.frames[round(args[0] * FPS)] = self.current
        self.current = {}


def start_server(port):
    return stage_start_server(server_bin, src, work, port)


def difference(sent, got):
    """Mean angle (degrees) between the performer's and the output's bones."""
    angles = [quat_angle(sent[b][1], got[b][1]) for b in sent if b in got]
    return math.degrees(sum(angles) / max(1, len(angles)))


grpc_port, vmc_in, vmc_out, vmc_out2 = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_DGRAM), \
    free_port(socket.SOCK_DGRAM), free_port(socket.SOCK_DGRAM)
server = start_server(grpc_port)
engine = Engine(vmc_out)
engine2 = Engine(vmc_out2)
cues = os.path.join(work, "show.cues")
with open(cues, "w") as f:
    f.write("# a cue early in the show\n0.3 strength 0.95\n")
bridge_log = open(os.path.join(work, "bridge.log"), "w")
bridge = subprocess.Popen([bridge_bin, "--server", "localhost:%d" % grpc_port, "--vmc-in", str(vmc_in),
                           "--vmc-out", "localhost:%d,localhost:%d" % (vmc_out, vmc_out2), "--style",
                           os.path.join(src, "samples", "walk_old.bvh"), "--fps", str(int(FPS)),
                           "--stats", "1", "--cues", cues, "--max-performers", "2"], stdout=bridge_log, stderr=subprocess.STDOUT)
performer = liblo.Address("localhost", vmc_in)
# Each performer sends from its own socket: the bridge tells them apart by
# source address.
first_performer, second_performer = liblo.Server(), liblo.Server()
sent = {}
try:
    time.sleep(0.5)

    def play(first, count, also_second=False):
        """Sends frames first..first+count-1 (the clip looped) at 60 Hz, from
        the first performer (and the same frames from the second)."""
        start = time.monotonic()
        for k in range(count):
            n = first + k
            bones = frames[n % len(frames)]
            bundle = liblo.Bundle()
            bundle.add(liblo.Message("/VMC/Ext/Root/Pos", "root", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))
            for name, (p, q) in bones.items():
                bundle.add(liblo.Message("/VMC/Ext/Bone/Pos", name, *p, *q))
            bundle.add(liblo.Message("/VMC/Ext/OK", 1))
            bundle.add(liblo.Message("/VMC/Ext/T", ("f", n / FPS)))
            first_performer.send(performer, bundle)
            if also_second:
                second_performer.send(performer, bundle)
            sent[n] = bones
            time.sleep(max(0.0, start + (k + 1) / FPS - time.monotonic()))
        return first + count

    n = play(0, 240)  # 4 s styled.
    time.sleep(0.3)
    with engine.lock:
        got = dict(engine.frames)
    received = len([t for t in range(n) if t in got])
    print("     the engine got %d of %d frames (the rest are the stream's look-ahead, still in flight)"
          % (received, n))
    check("the engine gets the frames (all but the stream's look-ahead, <= 4)", received >= n - 4,
          (received, n))
    check("with the performer's bones", all(set(got[t]) == set(sent[t]) for t in got if t < n),
          sorted(set(sent[0]) ^ set(got.get(10, {}))))
    check("and /VMC/Ext/OK", engine.ok >= n - 4, engine.ok)
    styled = [difference(sent[t], got[t]) for t in range(30, n - 4) if t in got]
    mean_styled = sum(styled) / max(1, len(styled))
    check("stylized: the output's bones differ from the performer's (mean > 2 degrees)",
          mean_styled > 2, mean_styled)

    # The server goes away: the performer passes through, unchanged.
    server.kill()
    server.wait()
    killed_at = n
    n = play(n, 90)
    time.sleep(0.3)
    with engine.lock:
        got = dict(engine.frames)
    passed = [difference(sent[t], got[t]) for t in range(killed_at + 10, n) if t in got]
    check("server down: every frame reaches the engine, those in flight included",
          all(t in got for t in range(killed_at - 4, n)),
          [t for t in range(killed_at - 4, n) if t not in got])
    check("server down: the performer passes through unchanged (< 0.01 degrees)",
          passed and max(passed) < 0.01, max(passed) if passed else None)

    # It comes back: styled frames resume within 2 s.
    server = start_server(grpc_port)
    back_at = n
    n = play(n, 180)
    time.sleep(0.3)
    with engine.lock:
        got = dict(engine.frames)
    resumed = next((t for t in range(back_at, n - 3) if t in got and difference(sent[t], got[t]) > 1.0),
                   None)
    check("server back: styled frames resume within 2 s", resumed is not None
          and (resumed - back_at) / FPS <= 2.0,
          None if resumed is None else (resumed - back_at) / FPS)
    if resumed is not None:
        print("     styled again %.2f s after the server was back" % ((resumed - back_at) / FPS))
    gaps = [t for t in range(0, n - 4) if t not in got]
    print("     frames the engine never saw: %d of %d %s" % (len(gaps), n - 4, gaps[:10]))
    check("the engine sees every frame, through the restart", not gaps, gaps[:10])

    # A second performer joins: its own stream, to the second engine.
    joined = n
    n = play(n, 120, also_second=True)
    time.sleep(0.3)
    with engine2.lock:
        got2 = dict(engine2.frames)
    second = [t for t in range(joined, n - 4) if t in got2]
    check("a second performer streams to the second engine",
          len(second) == n - 4 - joined and all(difference(sent[t], got2[t]) > 1.0 for t in second[20:]),
          (len(second), n - 4 - joined))

    # A third source, past --max-performers 2: refused, counted, no stream.
    third = liblo.Server()
    for k in range(30):
        third.send(performer, liblo.Bundle(
            liblo.Message("/VMC/Ext/Root/Pos", "root", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
            *[liblo.Message("/VMC/Ext/Bone/Pos", name, *p, *q) for name, (p, q) in frames[k].items()],
            liblo.Message("/VMC/Ext/T", ("f", k / FPS))))
        time.sleep(1 / FPS)

    # Strength 0 from the stage, with liblo's own oscsend.
    done = subprocess.run(["oscsend", "localhost", str(vmc_in), "/stylus/strength", "f", "0"],
                          capture_output=True, text=True)
    check("oscsend /stylus/strength 0", done.returncode == 0, done.stderr)
    before = n
    n = play(n, 120)
    time.sleep(0.3)
    with engine.lock:
        got = dict(engine.frames)
    weak = [difference(sent[t], got[t]) for t in range(before + 40, n - 3) if t in got]
    mean_weak = sum(weak) / max(1, len(weak))
    print("     mean bone difference: %.2f degrees styled, %.2f at strength 0" % (mean_styled, mean_weak))
    check("strength 0 brings the output towards the performer's", mean_weak < 0.6 * mean_styled,
          (mean_weak, mean_styled))
finally:
    bridge.terminate()
    try:
        bridge.wait(timeout=10)
    except subprocess.TimeoutExpired:
        bridge.kill()
    server.terminate()
    server.wait()
    engine.running = False
log = open(os.path.join(work, "bridge.log")).read()
stats = [line for line in log.splitlines() if line.startswith("performers")]
print("     " + (stats[-1] if stats else "(no counters printed)"))
check("the counters show the failure and the reconnect", stats and " reconnects 0" not in stats[-1]
      and " stream_failures 0" not in stats[-1], stats[-1] if stats else log[-500:])
check("the bridge stops on SIGTERM", bridge.returncode == 0, bridge.returncode)
check("a source past --max-performers is refused and counted",
      bool(stats) and " performers 2 " in " " + stats[-1] + " " and " refused 0 " not in stats[-1] + " ",
      stats[-1] if stats else None)
check("the cue file's strength change was played", "strength -> 0.95" in log, log[-300:])
check.finish()
