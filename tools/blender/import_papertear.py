"""Imports a papertear run into Blender: the animated sheet (DIR/animation.glb) or one frame's
mesh (a .glb from DIR/mesh/), with the scene's frame rate and frame range set from the file
and the node ids restored as integer point attributes "node" and "original_node".

In Blender's UI: Scripting > Open this file > Run Script, after setting RUN below; or
from a shell (Debian's Blender needs --python-exit-code to report a failed script):

    blender --python tools/blender/import_papertear.py -- OUT_DIR          # animation.glb
    blender --python tools/blender/import_papertear.py -- OUT_DIR/mesh/frame_0029.glb

papertear writes glTF y up in metres; Blender's importer turns it to z up, so in Blender the
sheet lies in its x-y plane, 1 simulation mm = 1 Blender mm (0.001 m).
"""
import json
import os
import struct
import sys

import numpy

# Debian 12's Blender 3.4 importer uses numpy.bool, which numpy 1.24 removed. (numpy 1.24
# warns on the look-up itself; the dictionary check does not.)
if "bool" not in vars(numpy):
    numpy.bool = bool

import bpy  # noqa: E402

RUN = ""  # for the UI: a run's output folder or a .glb; the command line's "-- PATH" wins
IDS_UV = "UVMap.001"  # TEXCOORD_1 = (node, original node), see tools/render/gltf_builder.hpp


def glb_json(path):
    """The JSON chunk of a .glb (for asset.extras: fps, frames)."""
    with open(path, "rb") as f:
        magic, _version, _length = struct.unpack("<III", f.read(12))
        if magic != 0x46546C67:
            raise RuntimeError(f"{path} is not a .glb")
        size, kind = struct.unpack("<II", f.read(8))
        return json.loads(f.read(size))


def restore_ids(obj):
    """Turns the ids UV map back into integer point attributes and drops it."""
    mesh = obj.data
    uv = mesh.uv_layers.get(IDS_UV)
    if uv is None:
        raise RuntimeError(f"{obj.name}: no node id UV map '{IDS_UV}' (not a papertear mesh?)")
    node = [0] * len(mesh.vertices)
    original = [0] * len(mesh.vertices)
    for loop, data in zip(mesh.loops, uv.data):
        # The importer flips v (v -> 1 - v); ids are integers below 2^24, so this is exact.
        node[loop.vertex_index] = round(data.uv[0])
        original[loop.vertex_index] = round(1.0 - data.uv[1])
    for name, values in (("node", node), ("original_node", original)):
        attr = mesh.attributes.get(name) or mesh.attributes.new(name, "INT", "POINT")
        attr.data.foreach_set("value", values)
    mesh.uv_layers.remove(uv)


def import_run(path):
    """Imports the run at `path` (folder or .glb); returns the sheet object (a per-frame
    file's fibres are the object "fibres" beside it)."""
    glb = os.path.join(path, "animation.glb") if os.path.isdir(path) else path
    extras = glb_json(glb).get("asset", {}).get("extras", {})
    scene = bpy.context.scene
    scene.render.fps = int(extras.get("fps", 24))  # before the import: keys land on whole frames
    scene.render.fps_base = 1.0
    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=glb)
    meshes = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    # The sheet, and in a per-frame file the frayed fibres as an object of their own.
    sheets = [o for o in meshes if o.name.startswith("sheet")]
    if len(sheets) != 1:
        raise RuntimeError(f"{glb}: expected one 'sheet' mesh, got {len(sheets)}")
    sheet = sheets[0]
    restore_ids(sheet)  # the fibres carry ids only as custom attributes
    keys = sheet.data.shape_keys
    if keys is not None and keys.animation_data and keys.animation_data.action:
        first, last = keys.animation_data.action.frame_range
        scene.frame_start, scene.frame_end = int(round(first)), int(round(last))
    else:  # one frame
        scene.frame_start = scene.frame_end = 1
    scene.frame_set(scene.frame_start)
    return sheet


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    path = argv[0] if argv else RUN
    if not path:
        raise SystemExit("import_papertear: give a run's output folder or a .glb after '--'")
    import_run(path)


if __name__ == "__main__":
    main()
