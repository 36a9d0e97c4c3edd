"""The Stylus client: one object per server (or list of servers), methods for
every call of the API. Clips go in and come out as :class:`~stylus_client.bvh.Clip`.

    from stylus_client import Client, read_bvh, write_bvh

    with Client("localhost:50051") as stylus:
        out = stylus.transfer(read_bvh("walk.bvh"), style=read_bvh("old.bvh"))
        write_bvh(out, "walk_old.bvh")
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Dict, Iterable, Iterator, List, Optional, Sequence, Union

import grpc
from stylus.v1 import stylus_pb2

from . import errors, wire
from .bvh import Clip

StyleLike = Union[Clip, str]
"""A style: a clip the server encodes, or the name of one saved with encode_style."""

_POSTPROCESS = {
    "default": stylus_pb2.POSTPROCESS_DEFAULT,
    "none": stylus_pb2.POSTPROCESS_NONE,
    "feet": stylus_pb2.POSTPROCESS_FEET,
    "full": stylus_pb2.POSTPROCESS_FULL,
}


@dataclass
class StreamFrame:
    """One stylized frame of a stream: the index of the input frame it was
    made from, its channel values on the input's skeleton, and the time from
    sending that input frame to receiving this one (seconds)."""

    index: int
    values: List[float]
    latency_s: float


@dataclass
class StyleChange:
    """From input frame ``frame`` on, a new style (a clip or saved name),
    blend (``weights`` over ``styles``) or ``strength`` (0..1), cross-faded
    over ``fade_frames`` (live models)."""

    frame: int
    style: Optional[StyleLike] = None
    styles: Optional[Sequence[StyleLike]] = None
    weights: Optional[Sequence[float]] = None
    strength: Optional[float] = None
    fade_frames: int = 0


def _read(path_or_bytes: Union[str, bytes, None]) -> Optional[bytes]:
    if path_or_bytes is None or isinstance(path_or_bytes, bytes):
        return path_or_bytes
    with open(path_or_bytes, "rb") as f:
        return f.read()


class Client:
    """A connection to a Stylus server.

    ``address``: ``host:port``, or ``dns:///name:port`` / ``ipv4:a:p,b:p`` for
    several servers (calls go round-robin over them). ``token``: sent as
    ``authorization: Bearer TOKEN``. TLS: ``tls_ca`` (a PEM path or bytes, or
    ``"system"`` for the system's roots) turns it on; ``tls_cert`` and
    ``tls_key`` add a client certificate (mutual TLS); ``server_name``
    overrides the name checked against the server's certificate.
    ``timeout``: seconds per call (streams: ten times that).
    """

    def __init__(self, address: str = "localhost:50051", *, token: Optional[str] = None,
                 tls_ca: Union[str, bytes, None] = None, tls_cert: Union[str, bytes, None] = None,
                 tls_key: Union[str, bytes, None] = None, server_name: Optional[str] = None,
                 timeout: float = 60.0, max_message_mb: int = 64):
        limit = max_message_mb << 20
        options = [("grpc.max_receive_message_length", limit),
                   ("grpc.max_send_message_length", limit),
                   ("grpc.lb_policy_name", "round_robin")]
        if server_name:
            options.append(("grpc.ssl_target_name_override", server_name))
        if tls_ca is not None or tls_cert is not None:
            roots = None if tls_ca in (None, "system") else _read(tls_ca)
            creds = grpc.ssl_channel_credentials(root_certificates=roots,
                                                 private_key=_read(tls_key),
                                                 certificate_chain=_read(tls_cert))
            self._channel = grpc.secure_channel(address, creds, options=options)
        else:
            self._channel = grpc.insecure_channel(address, options=options)
        self._timeout = timeout
        self._metadata = [("authorization", "Bearer " + token)] if token else []
        m = stylus_pb2.DESCRIPTOR.package
        self._calls = {}
        for service, method, request, response in [
                ("ModelService", "ListModels", stylus_pb2.ListModelsRequest, stylus_pb2.ListModelsResponse),
                ("ModelService", "GetModel", stylus_pb2.GetModelRequest, stylus_pb2.ModelInfo),
                ("ModelService", "LoadModel", stylus_pb2.LoadModelRequest, stylus_pb2.ModelInfo),
                ("ModelService", "UnloadModel", stylus_pb2.UnloadModelRequest, stylus_pb2.UnloadModelResponse),
                ("StyleService", "Transfer", stylus_pb2.TransferRequest, stylus_pb2.TransferResponse),
                ("StyleService", "EncodeStyle", stylus_pb2.EncodeStyleRequest, stylus_pb2.EncodeStyleResponse),
                ("StyleService", "Interpolate", stylus_pb2.InterpolateRequest, stylus_pb2.TransferResponse),
                ("StyleService", "ComputeMetrics", stylus_pb2.MetricsRequest, stylus_pb2.MetricsResponse)]:
            self._calls[method] = self._channel.unary_unary(
                "/%s.%s/%s" % (m, service, method), request_serializer=request.SerializeToString,
                response_deserializer=response.FromString)
        self._stream = self._channel.stream_stream(
            "/%s.StyleService/TransferStream" % m,
            request_serializer=stylus_pb2.StreamRequest.SerializeToString,
            response_deserializer=stylus_pb2.StreamResponse.FromString)
        self._health = self._channel.unary_unary("/grpc.health.v1.Health/Check")

    # -- plumbing --------------------------------------------------------

    def close(self) -> None:
        """Closes the connection."""
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _call(self, method: str, request):
        try:
            return self._calls[method](request, timeout=self._timeout, metadata=self._metadata)
        except grpc.RpcError as e:
            raise errors.from_rpc_error(e) from None

    @staticmethod
    def _postprocess(name: str) -> int:
        if name not in _POSTPROCESS:
            raise ValueError("postprocess must be one of %s, got %r" % (", ".join(_POSTPROCESS), name))
        return _POSTPROCESS[name]

    @staticmethod
    def _style_ref(style: StyleLike, ref: stylus_pb2.StyleRef,
                   joint_map: Optional[Dict[str, str]] = None) -> None:
        if isinstance(style, Clip):
            ref.clip.CopyFrom(wire.clip_to_proto(style, joint_map))
        elif isinstance(style, str) and style:
            ref.name = style
        else:
            raise TypeError("a style is a Clip or a saved style name, got %r" % (style,))

    # -- models ----------------------------------------------------------

    def health(self) -> bool:
        """True when the server says SERVING (grpc.health.v1; open without a token)."""
        try:
            reply = self._health(b"", timeout=self._timeout)
        except grpc.RpcError as e:
            raise errors.from_rpc_error(e) from None
        return reply == b"\x08\x01"

    def models(self) -> List[stylus_pb2.ModelInfo]:
        """Every model the server holds (id, family, skeleton, fps, live, saved_styles, ...)."""
        return list(self._call("ListModels", stylus_pb2.ListModelsRequest()).models)

    def model(self, name: str = "") -> stylus_pb2.ModelInfo:
        """One model (default: the server's default model)."""
        return self._call("GetModel", stylus_pb2.GetModelRequest(model=name))

    def load_model(self, name: str) -> stylus_pb2.ModelInfo:
        """Loads ``NAME/VERSION`` from the server's models directory."""
        return self._call("LoadModel", stylus_pb2.LoadModelRequest(model=name))

    def unload_model(self, name: str) -> None:
        self._call("UnloadModel", stylus_pb2.UnloadModelRequest(model=name))

    # -- style -----------------------------------------------------------

    def transfer(self, content: Clip, style: StyleLike, *, model: str = "",
                 postprocess: str = "default", joint_map: Optional[Dict[str, str]] = None,
                 timing: str = "content", fit_frames: int = 0) -> Clip:
        """``content`` with the style of ``style``, on the content's own skeleton
        (another humanoid rig is retargeted both ways; ``joint_map``:
        role -> joint name for roles not to guess, e.g. {"left_foot": "LFoot"}).

        ``timing="style"`` gives the output the style clip's cadence by a
        uniform time warp (its length changes); the returned clip's
        ``time_warp`` then says what was done: a dict with ``applied``,
        ``ratio`` (output duration / content duration), ``content_period_s``,
        ``style_period_s``, ``reason`` (why not, when not applied) and
        ``content_time_s`` (per output frame, the content instant it plays).
        With a package whose movement comes from examples (the default),
        ``timing="style"`` is a pace: the content's path at the example's
        speed, so the example's steps play as they were.
        ``fit_frames`` asks for exactly that many output frames (0.5-2x the
        content's).

        The returned clip's ``movement`` says where its movement came from
        (a dict with ``applied``, ``example``, ``kind``, ``fit``, ``reason``;
        None for a package whose movement is the network's), and
        ``contacts`` lists its own planted-foot spans as (joint, begin, end)."""
        if timing not in ("content", "style"):
            raise ValueError("timing must be 'content' or 'style', got %r" % timing)
        if fit_frames < 0:
            raise ValueError("fit_frames must be 0 (none) or a frame count, got %r" % fit_frames)
        request = stylus_pb2.TransferRequest(
            model=model, postprocess=self._postprocess(postprocess),
            timing=stylus_pb2.TIMING_STYLE if timing == "style" else stylus_pb2.TIMING_CONTENT,
            fit_frames=fit_frames)
        request.content.CopyFrom(wire.clip_to_proto(content, joint_map))
        self._style_ref(style, request.style, self._same_rig_map(style, content, joint_map))
        response = self._call("Transfer", request)
        out = wire.clip_from_proto(response.output)
        if timing == "style" or fit_frames:
            w = response.time_warp
            out.time_warp = {"applied": w.applied, "ratio": w.ratio,
                             "content_period_s": w.content_period_s,
                             "style_period_s": w.style_period_s, "reason": w.reason,
                             "content_time_s": list(w.content_time_s)}
        m = response.movement
        out.movement = ({"applied": m.applied, "example": m.example, "kind": m.kind,
                         "fit": m.fit, "reason": m.reason}
                        if response.HasField("movement") else None)
        out.contacts = [(c.joint, c.begin, c.end) for c in response.contacts]
        return out

    def interpolate(self, content: Clip, styles: Sequence[StyleLike], *,
                    weights: Optional[Sequence[float]] = None,
                    schedule: Optional[Sequence[Sequence[float]]] = None, model: str = "",
                    postprocess: str = "default",
                    joint_map: Optional[Dict[str, str]] = None) -> Clip:
        """``content`` with a blend of ``styles``: fixed ``weights`` (one per
        style) or a ``schedule`` (one row of weights per content frame)."""
        request = stylus_pb2.InterpolateRequest(model=model,
                                                postprocess=self._postprocess(postprocess))
        request.content.CopyFrom(wire.clip_to_proto(content, joint_map))
        for s in styles:
            self._style_ref(s, request.styles.add(), self._same_rig_map(s, content, joint_map))
        if weights is not None:
            request.weights.values.extend(weights)
        for row in schedule or []:
            request.schedule.add().values.extend(row)
        return wire.clip_from_proto(self._call("Interpolate", request).output)

    def encode_style(self, clip: Clip, *, save_as: str = "", model: str = "",
                     joint_map: Optional[Dict[str, str]] = None) -> List[float]:
        """The style code of ``clip``; with ``save_as``, saved on the server
        under that name (then usable as a style anywhere)."""
        request = stylus_pb2.EncodeStyleRequest(model=model, save_as=save_as)
        request.clip.CopyFrom(wire.clip_to_proto(clip, joint_map))
        return list(self._call("EncodeStyle", request).code)

    def metrics(self, output: Clip, content: Optional[Clip] = None,
                style: Optional[Clip] = None) -> Dict[str, float]:
        """Kinematic measures of ``output`` (foot skating, bone lengths,
        jitter, ...), and against ``content``/``style`` when given."""
        request = stylus_pb2.MetricsRequest()
        request.output.CopyFrom(wire.clip_to_proto(output))
        if content is not None:
            request.content.CopyFrom(wire.clip_to_proto(content))
        if style is not None:
            request.style.CopyFrom(wire.clip_to_proto(style))
        return dict(self._call("ComputeMetrics", request).metrics)

    def stream(self, content: Union[Clip, Iterable[Sequence[float]]], style: StyleLike, *,
               skeleton: Optional[Clip] = None, fps: Optional[float] = None,
               rate: Optional[float] = None, model: str = "", postprocess: str = "default",
               changes: Sequence[StyleChange] = (),
               joint_map: Optional[Dict[str, str]] = None) -> Iterator[StreamFrame]:
        """Streams frames and yields stylized frames as they come back, in order.

        ``content``: a Clip, or any iterable of channel rows (a live source)
        with ``skeleton`` (a Clip whose joints describe them) and ``fps``.
        ``rate``: frames sent per second (default: as fast as the iterable
        gives them; a Clip is sent at its own rate). ``changes``: style
        changes at input frames (live models).
        """
        rig = content if isinstance(content, Clip) else skeleton
        if rig is None:
            raise TypeError("stream: give a Clip, or frame rows with skeleton=")
        fps = fps or rig.fps
        rows = content.frames if isinstance(content, Clip) else content
        if rate is None and isinstance(content, Clip):
            rate = fps
        sent: Dict[int, float] = {}
        pending = sorted(changes, key=lambda c: c.frame)
        same_map = self._same_rig_map(style, rig, joint_map)

        def requests() -> Iterator[stylus_pb2.StreamRequest]:
            config = stylus_pb2.StreamRequest()
            c = config.config
            c.model, c.fps, c.postprocess = model, fps, self._postprocess(postprocess)
            c.skeleton.CopyFrom(wire.skeleton_to_proto(rig, joint_map))
            self._style_ref(style, c.style, same_map)
            yield config
            start = time.monotonic()
            for i, row in enumerate(rows):
                while pending and pending[0].frame <= i:
                    yield self._change_request(pending.pop(0), rig, joint_map)
                if rate:
                    delay = start + i / rate - time.monotonic()
                    if delay > 0:
                        time.sleep(delay)
                sent[i] = time.monotonic()
                yield stylus_pb2.StreamRequest(frame=wire.frame_to_proto(rig, row, i))

        try:
            responses = self._stream(requests(), timeout=10 * self._timeout, metadata=self._metadata)
            previous = None
            for r in responses:
                previous = wire.frame_from_proto(rig, r.frame, previous)
                yield StreamFrame(r.frame.index, previous,
                                  time.monotonic() - sent.get(r.frame.index, time.monotonic()))
        except grpc.RpcError as e:
            raise errors.from_rpc_error(e) from None

    # -- helpers ---------------------------------------------------------

    @staticmethod
    def _same_rig_map(style: StyleLike, content: Clip,
                      joint_map: Optional[Dict[str, str]]) -> Optional[Dict[str, str]]:
        """The content's joint map, for a style clip on the content's rig."""
        if joint_map and isinstance(style, Clip) and style.joint_names() == content.joint_names():
            return joint_map
        return None

    def _change_request(self, change: StyleChange, rig: Clip,
                        joint_map: Optional[Dict[str, str]]) -> stylus_pb2.StreamRequest:
        r = stylus_pb2.StreamRequest()
        c = r.change
        c.from_frame = change.frame
        c.fade_frames = change.fade_frames
        if change.strength is not None:
            c.strength = change.strength
        if change.style is not None:
            self._style_ref(change.style, c.style, self._same_rig_map(change.style, rig, joint_map))
        elif change.styles is not None:
            for s in change.styles:
                self._style_ref(s, c.blend.styles.add(), self._same_rig_map(s, rig, joint_map))
            c.blend.weights.extend(change.weights or [])
        return r
