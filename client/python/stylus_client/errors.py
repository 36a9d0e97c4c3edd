"""Typed errors: every failed call raises a :class:`StylusError` subclass
chosen by its gRPC status code; the message is the server's (it names the
clip, frame, joint or limit to fix)."""
from __future__ import annotations

import grpc


class StylusError(Exception):
    """A failed call. ``code`` is the grpc.StatusCode, ``details`` the server's message."""

    def __init__(self, code: grpc.StatusCode, details: str):
        super().__init__("%s: %s" % (code.name, details))
        self.code = code
        self.details = details


class InvalidArgument(StylusError):
    """Bad input: a malformed clip, a rig that is no humanoid, wrong weights."""


class NotFound(StylusError):
    """An unknown model or saved style name."""


class ResourceExhausted(StylusError):
    """A server limit: message size, streams, clip frames, saved styles."""


class Unauthenticated(StylusError):
    """No token, or one the server does not know."""


class PermissionDenied(StylusError):
    """The server refused the caller."""


class Unavailable(StylusError):
    """No server answered, or it is shutting down (retry on another)."""


class DeadlineExceeded(StylusError):
    """The call's deadline passed, or a stream sat idle too long."""


class FailedPrecondition(StylusError):
    """The call does not fit the state (e.g. a style change on an offline model's stream)."""


class Cancelled(StylusError):
    """The call was cancelled."""


class Internal(StylusError):
    """The server failed (a bug: report it with the request id from its log)."""


_BY_CODE = {
    grpc.StatusCode.INVALID_ARGUMENT: InvalidArgument,
    grpc.StatusCode.NOT_FOUND: NotFound,
    grpc.StatusCode.RESOURCE_EXHAUSTED: ResourceExhausted,
    grpc.StatusCode.UNAUTHENTICATED: Unauthenticated,
    grpc.StatusCode.PERMISSION_DENIED: PermissionDenied,
    grpc.StatusCode.UNAVAILABLE: Unavailable,
    grpc.StatusCode.DEADLINE_EXCEEDED: DeadlineExceeded,
    grpc.StatusCode.FAILED_PRECONDITION: FailedPrecondition,
    grpc.StatusCode.CANCELLED: Cancelled,
    grpc.StatusCode.INTERNAL: Internal,
}


def from_rpc_error(error: grpc.RpcError) -> StylusError:
    """The typed error of a failed gRPC call."""
    code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
    details = error.details() if hasattr(error, "details") else str(error)
    return _BY_CODE.get(code, StylusError)(code, details or "")
