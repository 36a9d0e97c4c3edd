#!/usr/bin/env python3
"""Restyle a BVH clip through a Stylus server, then stream it on the live model.

    python3 examples/transfer.py CONTENT.bvh STYLE.bvh OUT.bvh [--server HOST:PORT]
        [--token TOKEN] [--tls-ca CA.pem|system]

Writes OUT.bvh (the transfer, on CONTENT's own rig) and prints the live
stream's latency.
"""
import argparse
import os
import statistics
import sys

from stylus_client import Client, StylusError, read_clip, write_bvh


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("content")
    parser.add_argument("style")
    parser.add_argument("out")
    parser.add_argument("--server", default="localhost:50051")
    parser.add_argument("--token", default=None)
    parser.add_argument("--tls-ca", default=None, help="a CA file, or 'system'; turns TLS on")
    args = parser.parse_args()
    folder = os.path.dirname(os.path.abspath(args.out))
    if not os.path.isdir(folder):  # Before the call, so that no work is lost.
        parser.error("%s: the folder %s does not exist; create it first" % (args.out, folder))
    content, style = read_clip(args.content), read_clip(args.style)
    try:
        with Client(args.server, token=args.token, tls_ca=args.tls_ca) as stylus:
            print("server:", "SERVING" if stylus.health() else "NOT SERVING")
            print("models:", ", ".join(m.id for m in stylus.models()))
            out = stylus.transfer(content, style, postprocess="full")
            write_bvh(out, args.out)
            print("wrote %s (%d frames)" % (args.out, len(out.frames)))
            latencies = [f.latency_s for f in stylus.stream(content, style, model="live")]
            print("streamed %d frames on the live model; median latency %.1f ms"
                  % (len(latencies), 1000 * statistics.median(latencies)))
    except StylusError as e:
        print("stylus:", e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
