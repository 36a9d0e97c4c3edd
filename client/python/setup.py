"""Build step of the stylus-client package: protoc writes the API's Python
modules (stylus/v1/*_pb2.py) from the repository's proto/ into the build,
so the installed package always matches the .proto files it was built from."""
import os
import pathlib
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent
# The repository's proto/; $STYLUS_PROTO_DIR when the package is built from a copy.
PROTO_DIR = pathlib.Path(os.environ.get("STYLUS_PROTO_DIR", HERE.parent.parent / "proto"))
PROTOS = ["stylus/v1/motion.proto", "stylus/v1/stylus.proto"]


class BuildWithProtos(build_py):
    def run(self):
        super().run()
        protoc = shutil.which("protoc")
        if protoc is None:
            raise SystemExit("stylus-client: protoc not found (apt-get install protobuf-compiler)")
        out = pathlib.Path(self.build_lib)
        subprocess.check_call([protoc, "-I", str(PROTO_DIR), "--python_out", str(out)] + PROTOS)
        for package in (out / "stylus", out / "stylus" / "v1"):
            (package / "__init__.py").touch()


setup(cmdclass={"build_py": BuildWithProtos})
