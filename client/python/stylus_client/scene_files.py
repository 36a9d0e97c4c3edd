"""Clips from files other than BVH (FBX, glTF, COLLADA), read through the
``stylus`` CLI's ``convert`` (its assimp-based reader), since Debian has no
Python reader for them. BVH files are read directly."""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from typing import Optional

from .bvh import Clip, read_bvh

SCENE_EXTENSIONS = (".fbx", ".gltf", ".glb", ".dae")


def _stylus_cli() -> str:
    cli = os.environ.get("STYLUS_CLI") or shutil.which("stylus")
    if not cli:
        raise FileNotFoundError(
            "reading FBX, glTF or COLLADA needs the stylus CLI: put it on PATH or set STYLUS_CLI")
    return cli


def read_clip(path: str, animation: Optional[str] = None) -> Clip:
    """A clip from a .bvh, .fbx, .gltf, .glb or .dae file (``animation``:
    the one to read from a file with several)."""
    if not path.lower().endswith(SCENE_EXTENSIONS):
        return read_bvh(path)
    with tempfile.TemporaryDirectory(prefix="stylus-") as tmp:
        out = os.path.join(tmp, "clip.bvh")
        command = [_stylus_cli(), "convert", "--in", path, "-o", out]
        if animation:
            command += ["--animation", animation]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            raise ValueError(done.stderr.strip() or "stylus convert failed on %s" % path)
        return read_bvh(out)
