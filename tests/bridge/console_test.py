#!/usr/bin/python3
"""The stage console in a real headless Chromium (Debian's, driven by
Selenium through chromedriver): stylus-bridge --console against a real
server, a performer streaming a walk as VMC (python3-liblo) and an engine
receiving it.

Checks: the page renders both skeletons and they move (two screenshots
differ, and their middles are not blank); the style picker lists the styles
saved on the model; choosing one and pressing apply changes the stream's
style (the engine's frames at the same phase of the looping walk change,
where two earlier loops agree); the strength slider at 0 brings the output
back towards the performer's.

Usage: console_test.py STYLUS_SERVER STYLUS_BRIDGE STYLUS SOURCE_DIR WORK_DIR
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

server_bin, bridge_bin, cli, src, work = sys.argv[1:6]
ci = os.environ.get("CI") == "true"
if not (shutil.which("chromium") and shutil.which("chromedriver")):
    print(("FAIL: " if ci else "SKIP: ") + "Debian's chromium and chromium-driver are needed")
    sys.exit(1 if ci else 0)
from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.support.ui import Select  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stage_kit import Checks, build_dir_of, free_port, quat_angle, start_server, unity_bones, use_client  # noqa: E402
use_client(src, build_dir_of(bridge_bin))
from stylus_client.bvh import frame_pose, read_bvh  # noqa: E402

shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
check = Checks()


clip = read_bvh(os.path.join(src, "samples", "walk_normal.bvh"))
LOOP = len(clip.frames)
FPS = 60.0
sent_rotations = []
messages = []
for row in clip.frames:
    bones = unity_bones(clip, row, frame_pose)
    messages.append([liblo.Message("/VMC/Ext/Bone/Pos", name, *p, *q) for name, (p, q) in bones.items()])
    sent_rotations.append({name: q for name, (p, q) in bones.items()})

grpc_port, vmc_in, vmc_out, http_port = (free_port(socket.SOCK_STREAM), free_port(socket.SOCK_DGRAM),
                                         free_port(socket.SOCK_DGRAM), free_port(socket.SOCK_STREAM))
server = start_server(server_bin, src, work, grpc_port)
address = "localhost:%d" % grpc_port
subprocess.run([cli, "--server", address, "encode-style", "--model", "live", "--style",
                os.path.join(src, "samples", "run.bvh"), "--save-as", "run"], check=True,
               stdout=subprocess.DEVNULL)

frames = {}  # Frame number -> {bone: rotation}
lock = threading.Lock()
engine = liblo.Server(vmc_out)
current = {}


def on_bone(path, args):
    current[args[0]] = tuple(args[4:8])


def on_time(path, args):
    global current
    with lock:
        frames[round(args[0] * FPS)] = current
    current = {}


engine.add_method("/VMC/Ext/Bone/Pos", None, on_bone)
engine.add_method("/VMC/Ext/T", "f", on_time)
engine.add_method(None, None, lambda *a: None)
running = True


def receive():
    while running:
        engine.recv(10)


sent_count = [0]


def perform():
    target = liblo.Address("localhost", vmc_in)
    start = time.monotonic()
    n = 0
    while running:
        b = liblo.Bundle(liblo.Message("/VMC/Ext/Root/Pos", "root", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
                         *messages[n % LOOP], liblo.Message("/VMC/Ext/T", ("f", n / FPS)))
        liblo.send(target, b)
        n += 1
        sent_count[0] = n
        time.sleep(max(0.0, start + n / FPS - time.monotonic()))


bridge = subprocess.Popen([bridge_bin, "--server", address, "--vmc-in", str(vmc_in), "--vmc-out",
                           "localhost:%d" % vmc_out, "--style", os.path.join(src, "samples", "walk_old.bvh"),
                           "--fps", str(int(FPS)), "--console", "127.0.0.1:%d" % http_port],
                          stdout=open(os.path.join(work, "bridge.log"), "w"), stderr=subprocess.STDOUT)
threads = [threading.Thread(target=receive, daemon=True), threading.Thread(target=perform, daemon=True)]
for t in threads:
    t.start()


def loop_difference(loop_a, loop_b):
    """Mean angle (degrees) between the engine's frames of two loops of the
    walk, phase by phase."""
    with lock:
        got = dict(frames)
    angles = []
    for k in range(10, LOOP - 10):
        a, b = got.get(loop_a * LOOP + k), got.get(loop_b * LOOP + k)
        if a and b:
            angles += [quat_angle(a[n], b[n]) for n in a if n in b]
    return math.degrees(sum(angles) / max(1, len(angles))) if angles else None


def input_difference(loop):
    with lock:
        got = dict(frames)
    angles = []
    for k in range(LOOP):
        g = got.get(loop * LOOP + k)
        if g:
            angles += [quat_angle(g[n], sent_rotations[k][n]) for n in g if n in sent_rotations[k]]
    return math.degrees(sum(angles) / max(1, len(angles))) if angles else None


def wait_loop(loop):
    while sent_count[0] < (loop + 1) * LOOP + 10:
        time.sleep(0.05)


options = webdriver.ChromeOptions()
for a in ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
          "--disable-background-networking", "--disable-component-update", "--disable-sync",
          "--window-size=1200,700", "--user-data-dir=" + os.path.join(work, "chromium")]:
    options.add_argument(a)
options.binary_location = shutil.which("chromium")
browser = None
try:
    browser = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)
    browser.get("http://127.0.0.1:%d/" % http_port)
    time.sleep(2.0)
    first = os.path.join(work, "console_1.png")
    second = os.path.join(work, "console_2.png")
    browser.save_screenshot(first)
    time.sleep(0.7)
    browser.save_screenshot(second)
    check("the console renders and the skeletons move (two screenshots differ)",
          open(first, "rb").read() != open(second, "rb").read())
    drawn = browser.execute_script("""
        const c = document.getElementById('view');
        const g = c.getContext('webgl') || c.getContext('webgl2');
        const px = new Uint8Array(4 * c.width * c.height);
        g.readPixels(0, 0, c.width, c.height, g.RGBA, g.UNSIGNED_BYTE, px);
        let lit = 0;
        for (let i = 0; i < px.length; i += 4) if (px[i] > 120 || px[i + 2] > 120) ++lit;
        return lit;""")
    check("both skeletons are drawn (bright pixels in the view)", drawn > 200, drawn)
    counters = browser.execute_script("return document.getElementById('counters').textContent")
    check("the counters show the stream", "styled" in counters and "received 0 " not in counters, counters)

    wait_loop(3)
    steady = loop_difference(2, 3)
    # Choose the saved style "run" on the page.
    for _ in range(50):
        names = [o.text for o in Select(browser.find_element("id", "styles")).options]
        if "run" in names:
            break
        time.sleep(0.1)
    check("the style picker lists the model's saved styles", "run" in names, names)
    Select(browser.find_element("id", "styles")).select_by_visible_text("run")
    browser.find_element("id", "apply").click()
    time.sleep(0.3)
    shown = browser.execute_script("return document.getElementById('style').textContent")
    check("the page shows the new style", shown.startswith("run"), shown)
    changed_at = sent_count[0] // LOOP + 1
    wait_loop(changed_at)
    changed = loop_difference(changed_at - 2, changed_at)
    print("     the engine's walk, loop against loop: %.2f degrees before the change, %.2f across it"
          % (steady, changed))
    check("choosing a style on the page changes the stream's output",
          steady is not None and changed is not None and changed > 3 * steady + 1.0, (steady, changed))

    # The strength slider to 0.
    before = input_difference(changed_at)
    browser.execute_script("""
        const s = document.getElementById('strength');
        s.value = 0; s.dispatchEvent(new Event('input')); s.dispatchEvent(new Event('change'));""")
    weak_at = sent_count[0] // LOOP + 1
    wait_loop(weak_at)
    after = input_difference(weak_at)
    print("     output against the performer: %.2f degrees, %.2f at strength 0" % (before, after))
    check("the strength slider at 0 brings the output towards the performer's",
          before is not None and after is not None and after < 0.6 * before, (before, after))
finally:
    running = False
    if browser:
        browser.quit()
    bridge.terminate()
    bridge.wait(timeout=10)
    server.terminate()
    server.wait()
check.finish()
