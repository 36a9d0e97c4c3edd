#!/usr/bin/python3
"""The Python client package (client/python) against a real stylus-server.

Installs the package with pip into a fresh venv (--system-site-packages:
Debian's python3-grpcio and python3-protobuf), starts a server with TLS and
tokens, and runs every client method from that venv: health, models,
transfer (compared with the C++ CLI's output of the same call), interpolate,
encode-style and saved names, a live stream as a generator with a style
change, metrics, a clip on another rig, BVH read/write, typed errors.

Usage: python_package_test.py STYLUS_SERVER STYLUS_CLI SOURCE_DIR WORK_DIR
"""
import os
import shutil
import subprocess
import sys
import time


def setup_and_rerun(server_bin, cli, src, work):
    """Makes the venv, installs the package, starts the server, reruns inside."""
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    venv = os.path.join(work, "venv")
    subprocess.check_call(["/usr/bin/python3", "-m", "venv", "--system-site-packages", venv])
    py = os.path.join(venv, "bin", "python")
    # Built from a copy, so the build leaves nothing in the source tree.
    package = os.path.join(work, "package")
    shutil.copytree(os.path.join(src, "client", "python"), package,
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    install = subprocess.run([py, "-m", "pip", "install", "--no-build-isolation", "--no-index",
                              "--quiet", package], capture_output=True, text=True,
                             env=dict(os.environ, STYLUS_PROTO_DIR=os.path.join(src, "proto")))
    if install.returncode != 0:
        print("FAIL pip install:", install.stdout, install.stderr)
        return 1
    print("ok   pip install client/python into a venv")
    certs = os.path.join(work, "certs")
    subprocess.check_call([os.path.join(src, "tests", "server", "make_test_certs.sh"), certs],
                          stdout=subprocess.DEVNULL)
    with open(os.path.join(work, "tokens.txt"), "w") as f:
        f.write("# test token\nsecret-token-1\n")
    port_file = os.path.join(work, "port")
    log = open(os.path.join(work, "server.log"), "w")
    server = subprocess.Popen(
        [server_bin, "--models", os.path.join(src, "models"), "--listen", "localhost:0",
         "--port-file", port_file, "--auth-tokens", os.path.join(work, "tokens.txt"),
         "--tls-cert", os.path.join(certs, "server.pem"),
         "--tls-key", os.path.join(certs, "server.key")], stdout=log, stderr=log)
    try:
        for _ in range(600):
            if os.path.exists(port_file) and open(port_file).read().strip():
                break
            time.sleep(0.1)
        port = open(port_file).read().strip()
        env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
        # Run from the work dir: the package must come from the venv, not the sources.
        return subprocess.call([py, os.path.abspath(__file__), "--inside", port, cli, src, work],
                               cwd=work, env=env)
    finally:
        server.terminate()
        server.wait(timeout=60)


def inside(port, cli, src, work):
    import stylus_client
    from stylus_client import (BvhError, Client, InvalidArgument, NotFound, StyleChange,
                               Unauthenticated, Unavailable, read_bvh, write_bvh)
    from stylus_client.bvh import frame_pose

    failures = []

    def check(name, ok, detail=""):
        print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + str(detail)))
        if not ok:
            failures.append(name)

    check("the package is the installed one", "venv" in stylus_client.__file__,
          stylus_client.__file__)
    address = "localhost:" + port
    certs = os.path.join(work, "certs")
    stylus = Client(address, token="secret-token-1", tls_ca=os.path.join(certs, "ca.pem"))
    samples = os.path.join(src, "samples")
    walk = read_bvh(os.path.join(samples, "walk_normal.bvh"))
    old = read_bvh(os.path.join(samples, "walk_old.bvh"))
    run = read_bvh(os.path.join(samples, "run.bvh"))

    check("health", stylus.health() is True)
    ids = [m.id for m in stylus.models()]
    with open(os.path.join(src, "models", "DEFAULT")) as f:
        default = next(ln.strip() for ln in f if ln.strip() and not ln.startswith("#"))
    check("models", default in ids and "live/v3" in ids, ids)
    check("model", stylus.model("live").lookahead == 2)

    out = stylus.transfer(walk, old, postprocess="full")
    check("transfer: frames and joints", len(out.frames) == len(walk.frames)
          and out.joint_names() == walk.joint_names(), (len(out.frames), out.joint_names()[:3]))
    # The same call through the C++ CLI gives the same rotations.
    cli_out = os.path.join(work, "cli_out.bvh")
    subprocess.check_call([cli, "--server", address, "--token", "secret-token-1", "--tls-ca",
                           os.path.join(certs, "ca.pem"), "transfer", "--postprocess", "full",
                           "--content", os.path.join(samples, "walk_normal.bvh"), "--style",
                           os.path.join(samples, "walk_old.bvh"), "-o", cli_out],
                          stdout=subprocess.DEVNULL)
    reference = read_bvh(cli_out)
    worst = 0.0
    for a, b in zip(out.frames, reference.frames):
        ta, qa = frame_pose(out, a)
        tb, qb = frame_pose(reference, b)
        for p, q in zip(qa, qb):
            worst = max(worst, 1 - abs(sum(x * y for x, y in zip(p, q))))
        for p, q in zip(ta, tb):
            worst = max(worst, max(abs(x - y) for x, y in zip(p, q)))
    check("transfer equals the C++ client's", worst < 1e-6, worst)

    path = os.path.join(work, "py_out.bvh")
    write_bvh(out, path)
    back = read_bvh(path)
    check("write_bvh then read_bvh", back.frames == out.frames and back.joint_names() == out.joint_names())
    metrics = subprocess.run([cli, "--server", address, "--token", "secret-token-1", "--tls-ca",
                              os.path.join(certs, "ca.pem"), "metrics", "--output", path],
                             capture_output=True, text=True)
    check("the C++ CLI reads the BVH Python wrote", metrics.returncode == 0
          and "foot_skating" in metrics.stdout, metrics.stderr)

    try:
        write_bvh(out, os.path.join(work, "no_such_dir", "x.bvh"))
        check("write_bvh names a missing folder", False)
    except FileNotFoundError as e:
        check("write_bvh names a missing folder", "no_such_dir does not exist" in str(e), e)
    # FBX, glTF and COLLADA come through the CLI's reader: a glTF of the walk.
    from stylus_client import read_clip
    glb = os.path.join(work, "walk.glb")
    subprocess.check_call([cli, "convert", "--in", os.path.join(samples, "walk_normal.bvh"), "-o", glb],
                          stdout=subprocess.DEVNULL)
    os.environ["STYLUS_CLI"] = cli
    from_glb = read_clip(glb)
    check("read_clip reads a glTF through the CLI", from_glb.joint_names() == walk.joint_names()
          and len(from_glb.frames) == len(walk.frames), (from_glb.joint_names()[:2], len(from_glb.frames)))
    try:
        read_clip(os.path.join(work, "missing.fbx"))
        check("read_clip names a missing scene file", False)
    except ValueError as e:
        check("read_clip names a missing scene file", "missing.fbx" in str(e), e)

    blend = stylus.interpolate(walk, [old, run], weights=[0.5, 0.5])
    check("interpolate", len(blend.frames) == len(walk.frames))
    code = stylus.encode_style(old, save_as="old")
    check("encode_style", len(code) > 0)
    timed = stylus.transfer(walk, old, timing="style")
    check("style timing warps the output", timed.time_warp["applied"]
          and len(timed.frames) == round((len(walk.frames) - 1) * timed.time_warp["ratio"]) + 1
          and len(timed.frames) != len(walk.frames), (len(timed.frames), timed.time_warp))
    check("style timing maps each output frame to a content instant",
          len(timed.time_warp["content_time_s"]) == len(timed.frames)
          and timed.time_warp["content_time_s"][0] == 0, timed.time_warp["content_time_s"][:3])
    check("the package says where the movement came from", out.movement is not None
          and (out.movement["applied"] or out.movement["reason"]), out.movement)
    fitted = stylus.transfer(walk, old, fit_frames=len(walk.frames) + 30)
    check("fit_frames gives exactly that many frames", len(fitted.frames) == len(walk.frames) + 30,
          len(fitted.frames))
    named = stylus.transfer(walk, "old")
    check("transfer by saved name", len(named.frames) == len(walk.frames))

    frames = list(stylus.stream(walk, old, model="live", rate=0,
                                changes=[StyleChange(frame=60, strength=0.5, fade_frames=5)]))
    check("stream yields every frame in order",
          [f.index for f in frames] == list(range(len(walk.frames))), [f.index for f in frames][:5])
    check("stream frames carry values and latency",
          all(len(f.values) == walk.num_channels and f.latency_s >= 0 for f in frames))

    def live_rows():  # A live source: rows as they come, with their skeleton.
        for row in walk.frames[:40]:
            yield row
    stylus.encode_style(old, save_as="old", model="live")  # Saved names are per model.
    live = list(stylus.stream(live_rows(), "old", skeleton=walk, fps=30, model="live"))
    check("stream from a generator of rows", len(live) == 40, len(live))

    m = stylus.metrics(out, content=walk)
    check("metrics", "foot_skating" in m and "bone_length_error" in m, sorted(m)[:4])

    rigs = os.path.join(src, "..", "shared", "data", "rigs")
    if os.path.isdir(rigs):
        mixamo = read_bvh(os.path.join(rigs, "mixamo_55joints_30fps.bvh"))
        on_rig = stylus.transfer(mixamo, old)
        check("a Mixamo clip comes back on its rig", on_rig.joint_names() == mixamo.joint_names()
              and len(on_rig.frames) == len(mixamo.frames))
        try:
            stylus.transfer(mixamo, old, joint_map={"left_foot": "Nope"})
            check("a bad joint map is InvalidArgument", False, "no error")
        except InvalidArgument as e:
            check("a bad joint map is InvalidArgument", "left_foot = 'Nope'" in e.details, e)
    elif os.environ.get("CI") == "true":
        check("shared rigs present under CI", False, rigs)

    bandai = os.environ.get("STYLUS_DATA") or os.path.join(src, "..", "shared", "data", "bandai")
    if os.path.isdir(bandai):
        take = lambda name: read_bvh(os.path.join(bandai, "dataset-2", "dataset-2_%s.bvh" % name))
        normal = take("walk_normal_004")
        elderly = stylus.transfer(normal, take("walk_elderly_003"))
        check("an elderly walk's steps come from the style clip", elderly.movement["applied"]
              and elderly.movement["kind"] == "steps"
              and elderly.movement["example"] == "style clip", elderly.movement)
        check("the output's own contacts", len(elderly.contacts) > 4
              and all(0 <= b < e <= len(elderly.frames) for _, b, e in elderly.contacts),
              elderly.contacts[:4])
    elif os.environ.get("CI") == "true":
        check("Bandai data present under CI", False, bandai)

    def raises(name, kind, fn, text=""):
        try:
            fn()
            check(name, False, "no error")
        except kind as e:
            check(name, text in str(e), e)
        except Exception as e:  # noqa: BLE001
            check(name, False, "%s: %s" % (type(e).__name__, e))

    raises("unknown model is NotFound", NotFound, lambda: stylus.transfer(walk, old, model="nope/v1"))
    raises("bad timing is a ValueError", ValueError, lambda: stylus.transfer(walk, old, timing="beat"))
    raises("fit_frames out of range is InvalidArgument", InvalidArgument,
           lambda: stylus.transfer(walk, old, fit_frames=5 * len(walk.frames)), "fit_frames")
    three = read_bvh(os.path.join(src, "tests", "fixtures", "bvh", "good", "three_joint.bvh"))
    raises("a rig that is no humanoid is InvalidArgument", InvalidArgument,
           lambda: stylus.transfer(three, old), "not a humanoid rig")
    no_token = Client(address, tls_ca=os.path.join(certs, "ca.pem"))
    raises("no token is Unauthenticated", Unauthenticated, lambda: no_token.models())
    check("health needs no token", no_token.health() is True)
    plain = Client(address, token="secret-token-1", timeout=5)
    raises("plain text against TLS is Unavailable", Unavailable, lambda: plain.models())
    raises("a bad BVH names file and line", BvhError,
           lambda: read_bvh(os.path.join(src, "tests", "fixtures", "bvh", "bad", "nan_value.bvh")),
           "nan_value.bvh:25")
    raises("a bad postprocess is a ValueError", ValueError,
           lambda: stylus.transfer(walk, old, postprocess="wobbly"))
    example = subprocess.run(
        [sys.executable, os.path.join(src, "client", "python", "examples", "transfer.py"),
         os.path.join(samples, "walk_normal.bvh"), os.path.join(samples, "walk_old.bvh"),
         os.path.join(work, "example_out.bvh"), "--server", address, "--token", "secret-token-1",
         "--tls-ca", os.path.join(certs, "ca.pem")], capture_output=True, text=True)
    check("the example script runs", example.returncode == 0
          and "streamed 120 frames on the live model" in example.stdout,
          example.stdout + example.stderr)
    stylus.close()
    print("%d failed" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--inside":
        sys.exit(inside(*sys.argv[2:6]))
    sys.exit(setup_and_rerun(*sys.argv[1:5]))
