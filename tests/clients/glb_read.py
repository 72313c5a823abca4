"""A .glb's JSON and its FLOAT/UINT accessors as numpy arrays (for the client tests)."""
import json
import struct

import numpy

_TYPES = {5126: numpy.float32, 5125: numpy.uint32}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}


class Glb:
    def __init__(self, path):
        with open(path, "rb") as f:
            data = f.read()
        magic, _version, _length = struct.unpack_from("<III", data, 0)
        assert magic == 0x46546C67, f"{path}: not a .glb"
        size, _ = struct.unpack_from("<II", data, 12)
        self.json = json.loads(data[20:20 + size])
        offset = 20 + size
        bin_size, _ = struct.unpack_from("<II", data, offset)
        self.bin = data[offset + 8:offset + 8 + bin_size]

    def accessor(self, index):
        a = self.json["accessors"][index]
        view = self.json["bufferViews"][a["bufferView"]]
        width = _WIDTH[a["type"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        values = numpy.frombuffer(self.bin, _TYPES[a["componentType"]], a["count"] * width, start)
        return values.reshape(a["count"], width) if width > 1 else values

    def sheet(self):
        """Positions, node ids and original node ids of mesh "sheet" (mesh 0; the frayed
        fibres, when there, are mesh "fibres")."""
        mesh = self.json["meshes"][0]
        assert mesh["name"] == "sheet"
        attrs = mesh["primitives"][0]["attributes"]
        return (self.accessor(attrs["POSITION"]), self.accessor(attrs["_NODE"]).astype(int),
                self.accessor(attrs["_ORIGINAL_NODE"]).astype(int))


def gltf_to_blender(p):
    """Blender's importer turns glTF's y up into z up: (x, y, z) -> (x, -z, y)."""
    return numpy.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1)
