"""Packs the Blender add-on as a zip Blender installs (Edit > Preferences >
Add-ons > Install): stylus_blender/ with the Python client and the API's
generated modules under stylus_blender/vendor/.

usage: make_addon.py OUT.zip GENERATED_PYTHON_DIR
(GENERATED_PYTHON_DIR holds stylus/v1/*_pb2.py, as the build's protoc writes it)
"""
import pathlib
import sys
import zipfile

here = pathlib.Path(__file__).resolve().parent
out, generated = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
client = here.parent / "python" / "stylus_client"
entries = [(p, "stylus_blender/" + p.name) for p in sorted((here / "stylus_blender").glob("*.py"))]
entries += [(p, "stylus_blender/vendor/stylus_client/" + p.name) for p in sorted(client.glob("*.py"))]
entries += [(p, "stylus_blender/vendor/stylus/v1/" + p.name)
            for p in sorted((generated / "stylus" / "v1").glob("*_pb2.py"))]
if not any(name.endswith("stylus_pb2.py") for _, name in entries):
    sys.exit("make_addon.py: no stylus_pb2.py under %s" % generated)
tmp = out.with_suffix(".tmp")
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
    for path, name in entries:
        z.write(path, name)
    for package in ("stylus_blender/vendor/stylus/", "stylus_blender/vendor/stylus/v1/"):
        z.writestr(package + "__init__.py", "")
tmp.replace(out)
print("wrote %s (%d files)" % (out, len(entries) + 2))
