#!/usr/bin/env python3
"""instances.py OUT_DIR: a glTF scene of instances, written twice, for the tests of instancing
(tests/regress/instances.sh): inst.gltf places its meshes by instances (several nodes using
one mesh, nested transforms with a non-uniform scale and a mirror, EXT_mesh_gpu_instancing
with TRANSLATION, ROTATION and SCALE), and flat.gltf is the same scene with every placement a
mesh of its own (the same accessors under another mesh: each used once, so the loader bakes
it into world space as it bakes any mesh). The two must render alike.

The scene: a ground quad used once (world geometry beside the instances); a UV sphere with
a normal map placed three times (one through a mirroring parent); a cube placed 12 times by
EXT_mesh_gpu_instancing under a turned parent; an alpha-masked checker quad placed twice; an
emissive quad placed twice with scales that change its area, the scene's only light.

Also written: inst-short.gltf (the ROTATION accessor as normalized signed shorts, the
quantized form the extension allows), inst-anim.gltf (inst.gltf animated: a parent of
instances turns, an instance and a mesh used once move) and bad-*.gltf, each with one error in the extension,
whose message must name the JSON path (bad.txt lists file, path).

instances.py flatten IN.gltf OUT.gltf: any file, flattened (below)."""
import base64
import json
import math
import os
import struct
import sys
import zlib


def flatten(src, dst):
    """instances.py flatten IN.gltf OUT.gltf: IN with every EXT_mesh_gpu_instancing instance a
    child node of its own (its T R S) and every use of a mesh a mesh of its own, the buffers
    embedded: the same scene with nothing instanced."""
    d = json.load(open(src))
    bufs = []
    for b in d["buffers"]:
        uri = b["uri"]
        if uri.startswith("data:"):
            bufs.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            bufs.append(open(os.path.join(os.path.dirname(src), uri), "rb").read())
        b["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bufs[-1]).decode()

    def read(a):
        acc = d["accessors"][a]
        n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc["type"]]
        fmt, size, scale = {5126: ("f", 4, None), 5120: ("b", 1, 127.0), 5121: ("B", 1, 255.0),
                            5122: ("h", 2, 32767.0), 5123: ("H", 2, 65535.0)}[acc["componentType"]]
        v = d["bufferViews"][acc["bufferView"]]
        stride = v.get("byteStride", n * size)
        base = v.get("byteOffset", 0) + acc.get("byteOffset", 0)
        data = bufs[v["buffer"]]
        out = []
        for i in range(acc["count"]):
            e = list(struct.unpack_from("<%d%s" % (n, fmt), data, base + i * stride))
            out.append([max(x / scale, -1.0) for x in e] if scale and acc.get("normalized") else e)
        return out

    for i, node in enumerate(list(d["nodes"])):
        ext = node.get("extensions", {}).pop("EXT_mesh_gpu_instancing", None)
        if ext is None:
            continue
        attrs = ext["attributes"]
        cols = {k: read(a) for k, a in attrs.items() if k in ("TRANSLATION", "ROTATION", "SCALE")}
        count = len(next(iter(cols.values())))
        for j in range(count):
            child = {"mesh": node["mesh"]}
            for k, key in (("TRANSLATION", "translation"), ("ROTATION", "rotation"), ("SCALE", "scale")):
                if k in cols:
                    child[key] = cols[k][j]
            d["nodes"].append(child)
            node.setdefault("children", []).append(len(d["nodes"]) - 1)
        del node["mesh"]
    for node in d["nodes"]:  # every use of a mesh: a mesh of its own on the same accessors
        if "mesh" in node:
            d["meshes"].append(json.loads(json.dumps(d["meshes"][node["mesh"]])))
            node["mesh"] = len(d["meshes"]) - 1
    for k in ("extensionsUsed", "extensionsRequired"):
        if k in d:
            d[k] = [e for e in d[k] if e != "EXT_mesh_gpu_instancing"]
    json.dump(d, open(dst, "w"))


if sys.argv[1] == "flatten":
    flatten(sys.argv[2], sys.argv[3])
    sys.exit(0)

out = sys.argv[1]
os.makedirs(out, exist_ok=True)

# ---- geometry -------------------------------------------------------------------------------


def sphere(slices=24, stacks=12):
    pos, nrm, uv, idx = [], [], [], []
    for j in range(stacks + 1):
        th = math.pi * j / stacks
        for i in range(slices + 1):
            ph = 2 * math.pi * i / slices
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            pos += [0.5 * c for c in n]
            nrm += list(n)
            uv += [i / slices, j / stacks]
    for j in range(stacks):
        for i in range(slices):
            a, b = j * (slices + 1) + i, (j + 1) * (slices + 1) + i
            if j > 0:
                idx += [a, a + 1, b]
            if j < stacks - 1:
                idx += [a + 1, b + 1, b]
    return pos, nrm, uv, idx


def cube():
    pos, nrm, uv, idx = [], [], [], []
    faces = [((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]
    for n, u, v in faces:
        base = len(pos) // 3
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos += [0.5 * (n[k] + su * u[k] + sv * v[k]) for k in range(3)]
            nrm += list(n)
            uv += [(su + 1) / 2, (1 - sv) / 2]
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, uv, idx


def quad(size, up):
    """A square of side `size` in the xz plane facing +y (up) or -y."""
    h = size / 2
    pos = [-h, 0, -h, h, 0, -h, h, 0, h, -h, 0, h]
    ny = 1 if up else -1
    nrm = [0, ny, 0] * 4
    uv = [0, 0, 1, 0, 1, 1, 0, 1]
    idx = [0, 2, 1, 0, 3, 2] if up else [0, 1, 2, 0, 2, 3]
    return pos, nrm, uv, idx


def png(w, h, pixel):
    raw = b"".join(b"\0" + bytes(sum((list(pixel(x, y)) for x in range(w)), [])) for y in range(h))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def normal_map(x, y):
    """Bumps: a tangent-space normal tilted in u and v by a sine pattern."""
    nx, ny = 0.5 * math.sin(2 * math.pi * x / 8), 0.5 * math.sin(2 * math.pi * y / 8)
    nz = math.sqrt(max(0.0, 1 - nx * nx - ny * ny))
    return (int(127.5 + 127.5 * nx), int(127.5 + 127.5 * ny), int(127.5 + 127.5 * nz), 255)


def checker(x, y):
    on = ((x // 4) + (y // 4)) % 2 == 0
    return (230, 200, 60, 255 if on else 0)


def quat(axis, deg):
    a = math.radians(deg) / 2
    n = math.sqrt(sum(c * c for c in axis))
    return [axis[0] / n * math.sin(a), axis[1] / n * math.sin(a), axis[2] / n * math.sin(a), math.cos(a)]


# ---- the document -----------------------------------------------------------------------------


class Doc:
    def __init__(self):
        self.d = {"asset": {"version": "2.0", "generator": "gonio tests/tool/instances.py"},
                  "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
                  "accessors": [], "bufferViews": [], "buffers": [], "images": [], "textures": [],
                  "samplers": [{"magFilter": 9729, "minFilter": 9729}]}
        self.bin = bytearray()

    def view(self, data):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.d["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.d["bufferViews"]) - 1

    def accessor(self, values, type_, comp=5126, normalized=False, minmax=False):
        n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[type_]
        fmt = {5126: "f", 5125: "I", 5122: "h", 5120: "b", 5123: "H"}[comp]
        a = {"bufferView": self.view(struct.pack("<%d%s" % (len(values), fmt), *values)),
             "componentType": comp, "count": len(values) // n, "type": type_}
        if normalized:
            a["normalized"] = True
        if minmax:
            a["min"] = [min(values[k::n]) for k in range(n)]
            a["max"] = [max(values[k::n]) for k in range(n)]
        self.d["accessors"].append(a)
        return len(self.d["accessors"]) - 1

    def mesh(self, geo, material):
        pos, nrm, uv, idx = geo
        prim = {"attributes": {"POSITION": self.accessor(pos, "VEC3", minmax=True),
                               "NORMAL": self.accessor(nrm, "VEC3"), "TEXCOORD_0": self.accessor(uv, "VEC2")},
                "indices": self.accessor(idx, "SCALAR", 5125), "material": material}
        self.d["meshes"].append({"primitives": [prim]})
        return len(self.d["meshes"]) - 1

    def material(self, **m):
        self.d["materials"].append(m)
        return len(self.d["materials"]) - 1

    def texture(self, data):
        self.d["images"].append({"uri": "data:image/png;base64," + base64.b64encode(data).decode()})
        self.d["textures"].append({"source": len(self.d["images"]) - 1, "sampler": 0})
        return len(self.d["textures"]) - 1

    def node(self, parent=None, **n):
        self.d["nodes"].append(n)
        i = len(self.d["nodes"]) - 1
        if parent is None:
            self.d["scenes"][0]["nodes"].append(i)
        else:
            self.d["nodes"][parent].setdefault("children", []).append(i)
        return i

    def text(self):
        d = json.loads(json.dumps(self.d))
        d["buffers"] = [{"byteLength": len(self.bin),
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.bin)).decode()}]
        for k in ("images", "textures"):
            if not d[k]:
                del d[k]
        return d


def build(flat, short_rotation=False):
    g = Doc()
    grey = g.material(name="ground", pbrMetallicRoughness={"baseColorFactor": [0.6, 0.6, 0.6, 1],
                                                           "metallicFactor": 0, "roughnessFactor": 0.8})
    bumpy = g.material(name="bumpy", normalTexture={"index": g.texture(png(32, 32, normal_map))},
                       pbrMetallicRoughness={"baseColorFactor": [0.3, 0.5, 0.8, 1], "metallicFactor": 0,
                                             "roughnessFactor": 0.4})
    red = g.material(name="red", pbrMetallicRoughness={"baseColorFactor": [0.8, 0.2, 0.15, 1],
                                                       "metallicFactor": 0.3, "roughnessFactor": 0.5})
    mask = g.material(name="mask", alphaMode="MASK", alphaCutoff=0.5, doubleSided=True,
                      pbrMetallicRoughness={"baseColorTexture": {"index": g.texture(png(16, 16, checker))},
                                            "metallicFactor": 0, "roughnessFactor": 0.9})
    glow = g.material(name="glow", emissiveFactor=[1, 0.9, 0.8], extensions={"KHR_materials_emissive_strength":
                                                                            {"emissiveStrength": 12}},
                      pbrMetallicRoughness={"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0})
    g.d["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    ground = g.mesh(quad(12, True), grey)
    ball = g.mesh(sphere(), bumpy)
    box = g.mesh(cube(), red)
    leaf = g.mesh(quad(1.2, True), mask)
    lamp = g.mesh(quad(1, False), glow)
    # each use of a shared mesh: the mesh itself, or (flat) a mesh of its own on the same accessors
    def use(m):
        if not flat:
            return m
        g.d["meshes"].append(json.loads(json.dumps(g.d["meshes"][m])))
        return len(g.d["meshes"]) - 1

    g.node(name="camera", camera=0, translation=[0, 3.2, 7.5], rotation=quat((1, 0, 0), -20))
    g.d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05, "aspectRatio": 1}}]
    g.node(name="ground", mesh=ground)
    # the sphere: plain, under a turned and squashed parent with a mirrored child, and turned
    g.node(name="ball 1", mesh=use(ball), translation=[-2.2, 0.5, 0.5])
    p = g.node(name="squash", translation=[0.2, 0.6, 1.2], rotation=quat((0, 1, 0), 35), scale=[1.6, 0.8, 1.1])
    g.node(p, name="ball 2 (mirrored)", mesh=use(ball), translation=[0.3, 0.1, 0], scale=[-1, 1, 1],
           rotation=quat((0, 0, 1), 20))
    g.node(name="ball 3", mesh=use(ball), translation=[2.3, 0.7, 0.2], rotation=quat((1, 1, 0), 70),
           scale=[1.3, 1.3, 1.3])
    # the alpha-masked quad, twice, upright
    g.node(name="leaf 1", mesh=use(leaf), translation=[-1.0, 0.9, 2.6], rotation=quat((1, 0, 0), 75))
    g.node(name="leaf 2", mesh=use(leaf), translation=[1.3, 0.8, 2.9], rotation=quat((1, 0.3, 0), 65),
           scale=[1, 1, 0.7])
    # the lamps: emissive quads facing down, scaled (their world areas 1.2 and 0.6)
    g.node(name="lamp 1", mesh=use(lamp), translation=[-0.8, 3.6, 0.8], scale=[1.5, 1, 0.8])
    g.node(name="lamp 2", mesh=use(lamp), translation=[1.6, 3.2, -0.4], scale=[0.5, 1, 1.2],
           rotation=quat((0, 0, 1), 15))
    # the cubes: EXT_mesh_gpu_instancing under a turned parent
    t, r, s = [], [], []
    for k in range(12):
        x, z = k % 4, k // 4
        t += [1.1 * x - 1.65, 0.25 + 0.1 * (k % 3), -1.2 * z]
        r += quat((0.2 * k + 0.1, 1, 0.3), 17 * k)
        s += [0.35 + 0.05 * (k % 2), 0.4 + 0.03 * k, 0.3]
    row = g.node(name="cubes", translation=[0, 0, -1.5], rotation=quat((0, 1, 0), -12))
    if flat:
        for k in range(12):
            g.node(row, name="cube %d" % k, mesh=use(box), translation=t[3 * k:3 * k + 3],
                   rotation=r[4 * k:4 * k + 4], scale=s[3 * k:3 * k + 3])
    else:
        if short_rotation:
            rot = g.accessor([round(c * 32767) for c in r], "VEC4", 5122, normalized=True)
        else:
            rot = g.accessor(r, "VEC4")
        g.d["nodes"][row]["mesh"] = box
        g.d["nodes"][row]["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": {
            "TRANSLATION": g.accessor(t, "VEC3"), "ROTATION": rot, "SCALE": g.accessor(s, "VEC3"),
            "_ID": g.accessor([float(k) for k in range(12)], "SCALAR")}}}
        g.d["extensionsUsed"].append("EXT_mesh_gpu_instancing")
    return g.text()


def save(d, name):
    with open(os.path.join(out, name), "w") as f:
        json.dump(d, f)


save(build(False), "inst.gltf")
save(build(True), "flat.gltf")
save(build(False, short_rotation=True), "inst-short.gltf")


def animated():
    """inst.gltf, animated over 2 s: the cubes' parent turns, a lamp and the ground (a mesh used
    once: baked, or for --frames an instance) move."""
    d = build(False)
    names = {n.get("name"): i for i, n in enumerate(d["nodes"])}
    raw = bytearray(base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1]))

    def acc(values, type_):
        while len(raw) % 4:
            raw.append(0)
        data = struct.pack("<%df" % len(values), *values)
        d["bufferViews"].append({"buffer": 0, "byteOffset": len(raw), "byteLength": len(data)})
        raw.extend(data)
        n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[type_]
        a = {"bufferView": len(d["bufferViews"]) - 1, "componentType": 5126, "count": len(values) // n, "type": type_}
        if type_ == "SCALAR":
            a["min"], a["max"] = [min(values)], [max(values)]
        d["accessors"].append(a)
        return len(d["accessors"]) - 1

    t = acc([0.0, 1.0, 2.0], "SCALAR")
    tracks = [("cubes", "rotation", acc(quat((0, 1, 0), -12) + quat((0, 1, 0), 10) + quat((0, 1, 0), 40), "VEC4")),
              ("lamp 1", "translation", acc([-0.8, 3.6, 0.8, -0.2, 3.4, 0.9, 0.4, 3.6, 0.5], "VEC3")),
              ("ground", "translation", acc([0, 0, 0, 0, -0.1, 0.2, 0, -0.2, 0], "VEC3"))]
    d["animations"] = [{"name": "move", "samplers": [{"input": t, "output": o, "interpolation": "LINEAR"}
                                                     for _, _, o in tracks],
                        "channels": [{"sampler": k, "target": {"node": names[n], "path": p}}
                                     for k, (n, p, _) in enumerate(tracks)]}]
    d["buffers"][0] = {"byteLength": len(raw),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(raw)).decode()}
    return d


save(animated(), "inst-anim.gltf")

# ---- files with one error in the extension: the message names the JSON path -----------------
base = build(False)
row = next(i for i, n in enumerate(base["nodes"]) if "extensions" in n)
attrs = lambda d: d["nodes"][row]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]
where = "nodes[%d].extensions.EXT_mesh_gpu_instancing" % row
bad = []


def variant(name, path, edit):
    d = json.loads(json.dumps(base))
    edit(d)
    save(d, "bad-%s.gltf" % name)
    bad.append((name, path))


def wrong_type(d):  # TRANSLATION as VEC4
    d["accessors"][attrs(d)["TRANSLATION"]]["type"] = "VEC4"
    d["accessors"][attrs(d)["TRANSLATION"]]["count"] = 9


def byte_scale(d):  # SCALE as unsigned bytes: only floats are allowed
    a = d["accessors"][attrs(d)["SCALE"]]
    a["componentType"] = 5121
    a["count"] = 12


def plain_short_rotation(d):  # ROTATION as shorts that are not normalized
    a = d["accessors"][attrs(d)["ROTATION"]]
    a["componentType"] = 5122


def short_count(d):  # SCALE with fewer elements than TRANSLATION
    d["accessors"][attrs(d)["SCALE"]]["count"] = 5


def no_accessor(d):
    attrs(d)["ROTATION"] = 999


def no_mesh(d):
    del d["nodes"][row]["mesh"]


def not_object(d):
    d["nodes"][row]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = [1, 2]


variant("type", where + ".attributes.TRANSLATION", wrong_type)
variant("scale-bytes", where + ".attributes.SCALE", byte_scale)
variant("rotation-shorts", where + ".attributes.ROTATION", plain_short_rotation)
variant("count", where + ".attributes.SCALE", short_count)
variant("accessor", where + ".attributes.ROTATION", no_accessor)
variant("mesh", where, no_mesh)
variant("attributes", where + ".attributes", not_object)
with open(os.path.join(out, "bad.txt"), "w") as f:
    for name, path in bad:
        f.write("%s %s\n" % (name, path))
