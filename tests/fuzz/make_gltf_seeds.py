#!/usr/bin/env python3
"""Writes the committed glTF fuzz seeds (corpus/gltf/valid_*): small self-contained files (data URIs, GLB BIN
chunk) that each load, covering the loader's main paths. Deterministic; run from anywhere:
    python3 tests/fuzz/make_gltf_seeds.py"""
import base64, json, os, struct, zlib

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "gltf")


def data_uri(mime, raw):
    return "data:%s;base64,%s" % (mime, base64.b64encode(raw).decode())


def png_2x2():
    rows = b"".join(b"\x00" + bytes(px) for px in ([255, 0, 0, 255, 0, 255, 0, 255], [0, 0, 255, 255, 255, 255, 255, 128]))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


class Builder:
    """Accumulates one binary buffer and the bufferViews/accessors over it."""

    def __init__(self):
        self.bin, self.views, self.accessors = b"", [], []

    def add(self, fmt, values, ctype, atype, target=None, minmax=False, comps=1):
        while len(self.bin) % 4:
            self.bin += b"\x00"
        data = struct.pack("<%d%s" % (len(values), fmt), *values)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.views.append(view)
        self.bin += data
        acc = {"bufferView": len(self.views) - 1, "componentType": ctype, "count": len(values) // comps, "type": atype}
        if minmax:
            acc["min"] = [min(values[i::comps]) for i in range(comps)]
            acc["max"] = [max(values[i::comps]) for i in range(comps)]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def vec3(self, values):
        return self.add("f", values, 5126, "VEC3", 34962, True, 3)

    def vec2(self, values):
        return self.add("f", values, 5126, "VEC2", 34962, False, 2)

    def doc(self, extra):
        d = {"asset": {"version": "2.0", "generator": "nbvh make_gltf_seeds.py"},
             "buffers": [{"byteLength": len(self.bin), "uri": data_uri("application/octet-stream", self.bin)}],
             "bufferViews": self.views, "accessors": self.accessors}
        d.update(extra)
        return d


QUAD = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]


def triangle():
    b = Builder()
    pos = b.vec3([0, 0, 0, 1, 0, 0, 0, 1, 0])
    return b.doc({"scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "tri"}],
                  "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]})


def material_quad():
    b = Builder()
    pos = b.vec3(QUAD)
    nrm = b.vec3([0, 0, 1] * 4)
    idx = b.add("H", [0, 1, 2, 0, 2, 3], 5123, "SCALAR", 34963)
    return b.doc({
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "parent", "translation": [1, 2, 3], "rotation": [0, 0.7071068, 0, 0.7071068],
                   "scale": [2, 2, 2], "children": [1]},
                  {"name": "quad", "mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1]}],
        "meshes": [{"name": "quad", "primitives": [
            {"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx, "material": 0},
            {"attributes": {"POSITION": pos}, "mode": 6, "material": 1},   # the same quad as a fan
            {"attributes": {"POSITION": pos}, "mode": 1}]}],                # lines: skipped with a warning
        "materials": [
            {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.8, 0.3, 1], "metallicFactor": 1,
                                                      "roughnessFactor": 0.3},
             "emissiveFactor": [0.1, 0.1, 0], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
             "doubleSided": True},
            {"name": "glass", "alphaMode": "MASK", "alphaCutoff": 0.25,
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.9}}}],
        "extensionsUsed": ["KHR_materials_emissive_strength", "KHR_materials_transmission"]})


def textured():
    b = Builder()
    pos = b.vec3(QUAD)
    uv = b.vec2([0, 1, 1, 1, 1, 0, 0, 0])
    idx = b.add("B", [0, 1, 2, 0, 2, 3], 5121, "SCALAR", 34963)
    tex = {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 0.3, "scale": [2, 2]}}}
    return b.doc({
        "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "quad", "mesh": 0}, {"name": "cam", "camera": 0, "translation": [0.5, 0.5, 3]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1.5}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "indices": idx, "material": 0}]}],
        "materials": [{"name": "checker", "pbrMetallicRoughness": {"baseColorTexture": tex,
                                                                   "metallicRoughnessTexture": {"index": 0}},
                       "normalTexture": {"index": 0, "scale": 0.5}, "emissiveTexture": {"index": 0}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33648}],
        "images": [{"name": "checker", "uri": data_uri("image/png", png_2x2())}],
        "extensionsUsed": ["KHR_texture_transform"]})


def neural_scene():
    # Two scenes: the main one and a "*_neural" list naming the neural node; a strip; a sparse accessor.
    b = Builder()
    pos = b.vec3(QUAD)
    sparse_idx = b.add("H", [2], 5123, "SCALAR")
    sparse_val = b.add("f", [1, 1, 0.5], 5126, "VEC3", None, False, 3)
    moved = {"bufferView": b.accessors[pos]["bufferView"], "componentType": 5126, "count": 4, "type": "VEC3",
             "sparse": {"count": 1, "indices": {"bufferView": b.accessors[sparse_idx]["bufferView"], "componentType": 5123},
                        "values": {"bufferView": b.accessors[sparse_val]["bufferView"]}}}
    b.accessors.append(moved)
    strip = b.add("I", [0, 1, 3, 2], 5125, "SCALAR", 34963)
    return b.doc({
        "scene": 0, "scenes": [{"name": "main", "nodes": [0, 1]}, {"name": "scene_neural", "nodes": [2]}],
        "nodes": [{"name": "knot", "mesh": 0}, {"name": "floor", "mesh": 1, "translation": [0, -1, 0]},
                  {"name": "knot", "mesh": 0}],
        "meshes": [{"name": "knot", "primitives": [{"attributes": {"POSITION": len(b.accessors) - 2}, "indices": strip,
                                                    "mode": 5}]},
                   {"name": "floor", "primitives": [{"attributes": {"POSITION": pos}, "indices": strip, "mode": 5}]}]})


def skin_morph():
    # A quad skinned to two joints (the second rotated), with a morph target at default weights.
    b = Builder()
    pos = b.vec3(QUAD)
    joints = b.add("B", [0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0], 5121, "VEC4", 34962, False, 4)
    weights = b.add("f", [1, 0, 0, 0, 0.5, 0.5, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0], 5126, "VEC4", 34962, False, 4)
    identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    ibm = b.add("f", identity + identity[:12] + [-1, 0, 0, 1], 5126, "MAT4", None, False, 16)
    delta = b.vec3([0, 0, 0.5] * 4)
    idx = b.add("H", [0, 1, 2, 0, 2, 3], 5123, "SCALAR", 34963)
    return b.doc({
        "scene": 0, "scenes": [{"nodes": [0, 1, 3]}],
        "nodes": [{"name": "skinned", "mesh": 0, "skin": 0}, {"name": "root", "children": [2]},
                  {"name": "bone", "translation": [1, 0, 0], "rotation": [0, 0, 0.3826834, 0.9238795]},
                  {"name": "morphed", "mesh": 1, "weights": [0.75], "translation": [0, 2, 0]}],
        "skins": [{"joints": [1, 2], "inverseBindMatrices": ibm, "skeleton": 1}],
        "meshes": [{"name": "skin", "primitives": [{"attributes": {"POSITION": pos, "JOINTS_0": joints,
                                                                   "WEIGHTS_0": weights}, "indices": idx}]},
                   {"name": "morph", "weights": [0.5], "primitives": [{"attributes": {"POSITION": pos}, "indices": idx,
                                                                       "targets": [{"POSITION": delta}]}]}]})


def lights():
    # KHR_lights_punctual: a point light with range and colour, a spot under a scaled parent, a directional
    # light; a single-sided quad (back faces culled) under them.
    b = Builder()
    pos = b.vec3(QUAD)
    idx = b.add("H", [0, 1, 2, 0, 2, 3], 5123, "SCALAR", 34963)
    return b.doc({
        "scene": 0, "scenes": [{"nodes": [0, 1, 2, 4]}],
        "nodes": [{"name": "quad", "mesh": 0},
                  {"name": "bulb", "translation": [0.5, 0.5, 1], "extensions": {"KHR_lights_punctual": {"light": 0}}},
                  {"name": "rig", "scale": [2, 2, 2], "children": [3]},
                  {"name": "spot", "translation": [0, 0, 2], "extensions": {"KHR_lights_punctual": {"light": 1}}},
                  {"name": "sun", "rotation": [-0.3826834, 0, 0, 0.9238795],
                   "extensions": {"KHR_lights_punctual": {"light": 2}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx, "material": 0}]}],
        "materials": [{"name": "single", "doubleSided": False}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.9, 0.8], "intensity": 20, "range": 4},
            {"type": "spot", "intensity": 50, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
            {"type": "directional", "intensity": 3, "name": "sun"}]}},
        "extensionsUsed": ["KHR_lights_punctual"]})


def glb(doc_builder):
    d = doc_builder()
    raw = base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1])
    del d["buffers"][0]["uri"]
    js = json.dumps(d, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    raw += b"\x00" * (-len(raw) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(raw), b"BIN\x00") + raw
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def main():
    os.makedirs(OUT, exist_ok=True)
    files = {"valid_triangle.gltf": json.dumps(triangle(), indent=1).encode(),
             "valid_material_quad.gltf": json.dumps(material_quad(), indent=1).encode(),
             "valid_textured_quad.gltf": json.dumps(textured(), indent=1).encode(),
             "valid_neural_scene.gltf": json.dumps(neural_scene(), indent=1).encode(),
             "valid_skin_morph.gltf": json.dumps(skin_morph(), indent=1).encode(),
             "valid_lights.gltf": json.dumps(lights(), indent=1).encode(),
             "valid_material_quad.glb": glb(material_quad)}
    for name, data in files.items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)
        print("%s: %d bytes" % (name, len(data)))


if __name__ == "__main__":
    main()
