"""Python client of the Stylus motion style transfer service.

Read and write BVH (:func:`read_bvh`, :func:`write_bvh`; FBX, glTF and COLLADA
through the ``stylus`` CLI with :func:`read_clip`), and call a server
with :class:`Client`: transfer, interpolate, stream (a generator of stylized
frames), encode and save styles, metrics, models; TLS and tokens. Failed
calls raise typed errors (:mod:`stylus_client.errors`).
"""
from .bvh import BvhError, Clip, Joint, format_bvh, parse_bvh, read_bvh, write_bvh
from .client import Client, StreamFrame, StyleChange
from .scene_files import read_clip
from .errors import (Cancelled, DeadlineExceeded, FailedPrecondition, Internal, InvalidArgument,
                     NotFound, PermissionDenied, ResourceExhausted, StylusError, Unauthenticated,
                     Unavailable)

__all__ = [
    "BvhError", "Clip", "Joint", "format_bvh", "parse_bvh", "read_bvh", "read_clip", "write_bvh",
    "Client",
    "StreamFrame", "StyleChange", "StylusError", "InvalidArgument", "NotFound",
    "ResourceExhausted", "Unauthenticated", "PermissionDenied", "Unavailable",
    "DeadlineExceeded", "FailedPrecondition", "Cancelled", "Internal",
]
