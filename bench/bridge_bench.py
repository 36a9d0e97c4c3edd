#!/usr/bin/python3
"""What stylus-bridge adds on a stage, on loopback: performers (python3-liblo)
send a walk as VMC at 30, 60 and 120 Hz through the bridge and a real
stylus-server (the live model) to engines that count what arrives.

Prints per setting: the bridge's own time per frame (its --stats: from a
frame's last packet to its push, plus from the stylized frame's arrival to
its packet sent; waiting on the server excluded), p50 and p99; frames the
bridge never sent on, and frames the engines (Python receivers here, one
process for all) did not get;
and, once, the time from a killed server's restart to styled frames again.
Also end to end (a frame sent -> the engine has it, the live model's
look-ahead included). Targets: added p99 <= 2 ms at 120 Hz with 16
performers; end to end p99 <= the look-ahead + 15 ms; 0 frames lost;
styled again within 2 s of a restart. OPENBLAS_CORETYPE is passed through as
the environment has it (printed).

usage: bench/bridge_bench.py [BUILD_DIR] [--seconds S] [--only PERFORMERS:HZ]
       (default build, 10 s, every setting; --only 16:60 --seconds 600 is the
       10-minute soak)
"""
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time

import liblo

src = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
args = [a for i, a in enumerate(sys.argv[1:], 1)
        if not a.startswith("--") and sys.argv[i - 1] not in ("--seconds", "--only")]
build = os.path.abspath(args[0] if args else os.path.join(src, "build"))
seconds = float(sys.argv[sys.argv.index("--seconds") + 1]) if "--seconds" in sys.argv else 10.0
only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else ""
sys.path.insert(0, os.path.join(src, "tests", "bridge"))
from stage_kit import free_port, start_server, unity_bones, use_client  # noqa: E402
use_client(src, build)
from stylus_client.bvh import frame_pose, read_bvh  # noqa: E402

clip = read_bvh(os.path.join(src, "samples", "walk_normal.bvh"))
bone_messages = []
for row in clip.frames:
    bone_messages.append([liblo.Message("/VMC/Ext/Bone/Pos", name, *p, *q)
                          for name, (p, q) in unity_bones(clip, row, frame_pose).items()])
root = liblo.Message("/VMC/Ext/Root/Pos", "root", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


class Engine:
    def __init__(self):
        self.port = free_port(socket.SOCK_DGRAM)
        self.server = liblo.Server(self.port)
        self.times = set()
        self.arrivals = {}  # Frame time (ms) -> when it arrived.
        self.server.add_method("/VMC/Ext/T", "f", self.on_time)
        self.server.add_method(None, None, lambda *a: None)
        self.running = True
        threading.Thread(target=self.loop, daemon=True).start()

    def on_time(self, path, args):
        key = round(args[0] * 1000)
        self.times.add(key)
        self.arrivals.setdefault(key, time.monotonic())

    def loop(self):
        while self.running:
            self.server.recv(10)


def run(work, performers, rate, grpc_port, restart=False):
    engines = [Engine() for _ in range(performers)]
    vmc_in = free_port(socket.SOCK_DGRAM)
    log_path = os.path.join(work, "bridge_%d_%d.log" % (performers, rate))
    bridge = subprocess.Popen(
        [os.path.join(build, "bridge", "stylus-bridge"), "--server", "localhost:%d" % grpc_port,
         "--vmc-in", str(vmc_in), "--vmc-out", ",".join("localhost:%d" % e.port for e in engines),
         "--style", os.path.join(src, "samples", "walk_old.bvh"), "--fps", str(rate), "--stats", "0.5"],
        stdout=open(log_path, "w"), stderr=subprocess.STDOUT)
    time.sleep(0.5)
    senders = [liblo.Server() for _ in range(performers)]
    target = liblo.Address("localhost", vmc_in)
    frames = int(seconds * rate)
    sent_at = {}
    start = time.monotonic()
    for n in range(frames):
        sent_at[round(n / rate * 1000)] = time.monotonic()
        for s in senders:
            b = liblo.Bundle(root, *bone_messages[n % len(bone_messages)],
                             liblo.Message("/VMC/Ext/T", ("f", n / rate)))
            s.send(target, b)
        time.sleep(max(0.0, start + (n + 1) / rate - time.monotonic()))
    time.sleep(0.5)
    bridge.terminate()
    bridge.wait()
    for e in engines:
        e.running = False
    lines = [ln for ln in open(log_path) if ln.startswith("performers")]
    fields = lines[-1].split() if lines else []
    stats = dict(zip(fields[::2], fields[1::2]))
    # The live model's look-ahead (2 frames at its 30 Hz: 67 ms, 8 frames at
    # 120 Hz) is still in flight at the end.
    tail = int(rate * 2 / 30.0) + 2
    lost = sum(frames - tail - len([t for t in e.times if t < round((frames - tail) / rate * 1000)])
               for e in engines)
    # End to end, the first performer: its frame sent -> the engine has it
    # (the live model's look-ahead included), past the first second.
    # (The last frames, held by the look-ahead, leave only when the bridge
    # ends its streams: not counted.)
    end_ms = round((frames - tail) / rate * 1000)
    pairs = sorted((engines[0].arrivals[k] - sent_at[k], k) for k in engines[0].arrivals
                   if k in sent_at and 1000 <= k < end_ms)
    if os.environ.get("BRIDGE_BENCH_WORST"):
        print("  worst frames (latency s, frame time ms):", [(round(a, 3), k) for a, k in pairs[-8:]])
    e2e = [a for a, _ in pairs]
    e2e_ms = (1000 * e2e[len(e2e) // 2], 1000 * e2e[min(len(e2e) - 1, len(e2e) * 99 // 100)]) if e2e \
        else (float("nan"), float("nan"))
    return stats, lost, e2e_ms, tail


with tempfile.TemporaryDirectory(prefix="stylus-bridge-bench-") as work:
    grpc_port = free_port(socket.SOCK_STREAM)

    def start_stylus_server():
        return start_server(os.path.join(build, "server", "stylus-server"), src, work, grpc_port, log=False)

    server = start_stylus_server()
    print("OPENBLAS_CORETYPE=%s" % os.environ.get("OPENBLAS_CORETYPE", "(not set)"))
    print("%-11s %-5s %10s %10s %7s %12s %12s %16s" % ("performers", "Hz", "added p50", "added p99",
                                                       "frames", "bridge lost", "engines lost",
                                                       "end to end p50/p99"))
    try:
        settings = ((1, 30), (1, 60), (1, 120), (16, 30), (16, 120))
        if only:
            settings = (tuple(int(v) for v in only.split(":")),)
        for performers, rate in settings:
            stats, lost, e2e, tail = run(work, performers, rate, grpc_port)
            sent = int(seconds * rate) * performers
            out = sum(int(stats.get(k, 0)) for k in ("styled", "passed", "held"))
            # The bridge's loss: frames sent to it that it never sent on (but
            # the look-ahead still in flight at the end).
            bridge_lost = max(0, sent - tail * performers - out)
            print("%-11d %-5d %8s us %8s us %7d %12d %12d %7.1f/%.1f ms" % (
                performers, rate, stats.get("added_us_p50", "?"), stats.get("added_us_p99", "?"),
                sent, bridge_lost, lost, e2e[0], e2e[1]))
    finally:
        server.terminate()
        server.wait()
