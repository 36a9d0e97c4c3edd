#!/usr/bin/python3
"""A second-language client: Debian's python3-grpcio against a real stylus-server.

Calls grpc.health.v1 Health/Check, server reflection, ModelService/GetModel and
StyleService/Transfer (good and bad input), proving the proto works outside C++.
Messages come from protoc --python_out; methods are called by path, which
python3-grpcio allows without grpc_tools.

Usage: python_client_test.py STYLUS_SERVER SOURCE_DIR PYTHON_PROTO_DIR WORK_DIR
"""
import math
import os
import subprocess
import sys
import time

import grpc

server_bin, src, proto_dir, work = sys.argv[1:5]
sys.path.insert(0, proto_dir)
from stylus.v1 import stylus_pb2  # noqa: E402
from stylus.v1 import motion_pb2  # noqa: E402

failures = []
# The package models/DEFAULT names: what the server serves by default.
with open(os.path.join(src, "models", "DEFAULT")) as f:
    default = next(ln.strip() for ln in f if ln.strip() and not ln.startswith("#"))


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + str(detail)))
    if not ok:
        failures.append(name)


os.makedirs(work, exist_ok=True)
port_file = os.path.join(work, "port")
if os.path.exists(port_file):
    os.remove(port_file)
log = open(os.path.join(work, "server.log"), "w")
server = subprocess.Popen([server_bin, "--models", os.path.join(src, "models"), "--listen",
                           "localhost:0", "--port-file", port_file, "--reflection"],
                          stdout=log, stderr=log)
try:
    for _ in range(300):
        if os.path.exists(port_file) and open(port_file).read().strip():
            break
        time.sleep(0.1)
    port = int(open(port_file).read())
    channel = grpc.insecure_channel("localhost:%d" % port)
    ident = lambda b: b  # noqa: E731  (raw bytes in and out)

    # grpc.health.v1.Health/Check: HealthCheckRequest{} -> HealthCheckResponse{status=1 SERVING}.
    health = channel.unary_unary("/grpc.health.v1.Health/Check", request_serializer=ident,
                                 response_deserializer=ident)
    check("health SERVING", health(b"", timeout=10) == b"\x08\x01")

    # Server reflection (--reflection): list_services (field 7) lists our services.
    reflect = channel.stream_stream("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
                                    request_serializer=ident, response_deserializer=ident)
    reply = b"".join(reflect(iter([b"\x3a\x00"]), timeout=10))
    check("reflection lists StyleService", b"stylus.v1.StyleService" in reply, reply[:80])

    get_model = channel.unary_unary("/stylus.v1.ModelService/GetModel",
                                    request_serializer=stylus_pb2.GetModelRequest.SerializeToString,
                                    response_deserializer=stylus_pb2.ModelInfo.FromString)
    info = get_model(stylus_pb2.GetModelRequest(), timeout=10)
    check("GetModel default", info.id == default and len(info.skeleton.joints) == 22, info.id)

    # A 40-frame clip on the model's skeleton: the rest pose, gliding along x.
    def clip(skeleton, frames, fps):
        c = motion_pb2.Clip(skeleton=skeleton, fps=fps)
        root = skeleton.joints[0]
        for f in range(frames):
            fr = c.frames.add(index=f, timestamp=f / fps)
            fr.root_position.x = root.offset.x + 2.0 * f
            fr.root_position.y = root.offset.y
            fr.root_position.z = root.offset.z
            for j, joint in enumerate(skeleton.joints):
                fr.rotations.add(w=1.0)
                if j > 0 and any(ch.endswith("position") for ch in joint.channels):
                    fr.translations.add(x=joint.offset.x, y=joint.offset.y, z=joint.offset.z)
        return c

    transfer = channel.unary_unary("/stylus.v1.StyleService/Transfer",
                                   request_serializer=stylus_pb2.TransferRequest.SerializeToString,
                                   response_deserializer=stylus_pb2.TransferResponse.FromString)
    content = clip(info.skeleton, 40, info.fps)
    request = stylus_pb2.TransferRequest(content=content,
                                         style=stylus_pb2.StyleRef(clip=clip(info.skeleton, 50, info.fps)))
    out = transfer(request, timeout=60)
    check("Transfer frame count", len(out.output.frames) == 40, len(out.output.frames))
    q = out.output.frames[10].rotations[5]
    check("Transfer unit quaternions", abs(math.sqrt(q.w**2 + q.x**2 + q.y**2 + q.z**2) - 1) < 1e-6, q)
    check("Transfer names its model", out.model == default, out.model)
    check("Transfer says what the content guard did", out.HasField("content_guard") and
          (out.content_guard.residual_strength in (1, 0.7, 0.4, 0.2)), out.content_guard)

    bad = stylus_pb2.TransferRequest()
    bad.CopyFrom(request)
    del bad.content.frames[7].rotations[3:]
    try:
        transfer(bad, timeout=60)
        check("Transfer bad frame -> INVALID_ARGUMENT", False, "no error")
    except grpc.RpcError as e:
        check("Transfer bad frame -> INVALID_ARGUMENT",
              e.code() == grpc.StatusCode.INVALID_ARGUMENT and "frame 7" in e.details(), e.details())
    unknown = stylus_pb2.TransferRequest()
    unknown.CopyFrom(request)
    unknown.model = "nope/v1"
    try:
        transfer(unknown, timeout=60)
        check("Transfer unknown model -> NOT_FOUND", False, "no error")
    except grpc.RpcError as e:
        check("Transfer unknown model -> NOT_FOUND", e.code() == grpc.StatusCode.NOT_FOUND, e.details())
    channel.close()
finally:
    server.terminate()
    rc = server.wait(timeout=60)
    check("server exits 0 on SIGTERM", rc == 0, rc)

print("%d failed" % len(failures))
sys.exit(1 if failures else 0)
