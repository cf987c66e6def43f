"""gltf_fixture.py: the glTF files and images the tests write, built here (the Python standard
library only) so that a script says what its scene holds, not how glTF lays it out. lib.sh
puts tests/tool on PYTHONPATH: a script's Python does `import gltf_fixture as gf`.

    g = gf.Gltf()                                  # asset 2.0; one buffer, filled as views are added
    red = g.material({"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}})
    g.quad_view(g.quad(material=red))              # the quad [-1, 1]^2 and a camera it fills
    g.write(path)                                  # the buffer as a data: URI (bin=NAME: a file beside)

A Gltf is the document as the plain dict `g.doc` (edit it freely: a test of a broken file
breaks it there) and the bytes of one buffer, which every view added goes into, 4-byte
aligned (for a file read by Gltf.load, a new buffer after the file's own). Each add returns
the new object's index. box() and png() return numbers and bytes, for a script to work on
before adding them. As a command:

    gltf_fixture.py textured-glb OUT.glb IMAGE [FALLBACK.png]     (textured_glb, below)
"""
import base64
import json
import os
import struct
import sys
import zlib

# componentType
BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT, UNSIGNED_INT, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
# sampler filters and wrap modes
NEAREST, LINEAR = 9728, 9729
REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT = 10497, 33071, 33648
# bufferView targets
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963

_FORMAT = {BYTE: "b", UNSIGNED_BYTE: "B", SHORT: "h", UNSIGNED_SHORT: "H", UNSIGNED_INT: "I", FLOAT: "f"}
_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}

QUAD_POSITIONS = [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]  # Gltf.quad's, by default
QUAD_INDICES = [0, 1, 2, 0, 2, 3]


def pack(component, values):
    """values (a flat list) as little-endian componentType elements"""
    return struct.pack("<%d%s" % (len(values), _FORMAT[component]), *values)


def data_uri(data, mime="application/octet-stream"):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


class Gltf:
    def __init__(self, generator=None, doc=None):
        self.doc = doc if doc is not None else {"asset": {"version": "2.0"}}
        if generator:
            self.doc["asset"]["generator"] = generator
        self.data = bytearray()
        self.buffer = None  # the index of the buffer self.data fills, once a view is added

    @classmethod
    def load(cls, path):
        """a .gltf file to edit: views added go into a new buffer after its own"""
        with open(path) as f:
            return cls(doc=json.load(f))

    def add(self, kind, obj):
        """appends obj to the document's array `kind` ("skins", "animations", ...)"""
        self.doc.setdefault(kind, []).append(obj)
        return len(self.doc[kind]) - 1

    # ---- extensions ---------------------------------------------------------------------
    def use(self, *names):
        """names in extensionsUsed (once each, in the order given)"""
        used = self.doc.get("extensionsUsed", [])
        used += [n for n in names if n not in used]
        if used:
            self.doc["extensionsUsed"] = used

    def require(self, *names):
        """names in extensionsRequired, and so in extensionsUsed"""
        self.use(*names)
        req = self.doc.get("extensionsRequired", [])
        req += [n for n in names if n not in req]
        if req:
            self.doc["extensionsRequired"] = req

    def extend(self, obj, name, block=None, **fields):
        """obj's extension block `name` (block, or the fields), the extension declared used;
        returns the block, for fields added later"""
        block = dict(block or {}, **fields)
        obj.setdefault("extensions", {})[name] = block
        self.use(name)
        return block

    def declare_extensions(self):
        """every extension the document's objects name, in extensionsUsed (sorted)"""
        found = set()

        def walk(o):
            if isinstance(o, dict):
                found.update(o.get("extensions", {}))
                for v in o.values():
                    walk(v)
            elif isinstance(o, list):
                for v in o:
                    walk(v)
        walk({k: v for k, v in self.doc.items() if k not in ("extensions", "extensionsUsed", "extensionsRequired")})
        self.use(*sorted(found))

    def variants(self, *names):
        """KHR_materials_variants' variants, by name (a primitive's mappings: extend it)"""
        self.extend(self.doc, "KHR_materials_variants", variants=[{"name": n} for n in names])

    # ---- data ---------------------------------------------------------------------------
    def view(self, data, stride=None, target=None):
        """a buffer view of the bytes `data`, 4-byte aligned in the buffer"""
        if self.buffer is None:
            self.buffer = self.add("buffers", {})
        while len(self.data) % 4:
            self.data.append(0)
        v = {"buffer": self.buffer, "byteOffset": len(self.data), "byteLength": len(data)}
        if stride:
            v["byteStride"] = stride
        if target:
            v["target"] = target
        self.data += data
        self.doc["buffers"][self.buffer]["byteLength"] = len(self.data)
        return self.add("bufferViews", v)

    def accessor(self, values, type, component=FLOAT, count=None, bounds=False, stride=None, target=None,
                 view=None, **fields):
        """an accessor of `values` (a flat list of numbers, or bytes already packed) over a
        new view (or over `view`, values None); count by default all of values; bounds:
        min and max from the values; fields: more of the accessor (normalized, byteOffset,
        min, max, ...)"""
        n = _COMPONENTS[type]
        if view is None:
            view = self.view(values if isinstance(values, bytes) else pack(component, values), stride, target)
        a = {"bufferView": view, "componentType": component,
             "count": count if count is not None else len(values) // n, "type": type}
        if bounds:
            a["min"] = [min(values[k::n]) for k in range(n)]
            a["max"] = [max(values[k::n]) for k in range(n)]
        a.update(fields)
        return self.add("accessors", a)

    # ---- the scene ----------------------------------------------------------------------
    def mesh(self, *primitives, **fields):
        return self.add("meshes", dict({"primitives": list(primitives)}, **fields))

    def material(self, m):
        return self.add("materials", m)

    def sampler(self, mag=None, min=None, wrap=None):
        """a sampler with these filters and wrap = [S, T] (each None: left to the default)"""
        s = {}
        if wrap:
            s["wrapS"], s["wrapT"] = wrap
        if mag is not None:
            s["magFilter"] = mag
        if min is not None:
            s["minFilter"] = min
        return self.add("samplers", s)

    def texture(self, source=None, sampler=None, **fields):
        t = dict(fields)
        if source is not None:
            t["source"] = source
        if sampler is not None:
            t["sampler"] = sampler
        return self.add("textures", t)

    def image(self, data=None, uri=None, mime="image/png", in_buffer=False):
        """an image: `data` embedded as a data: URI (or, in_buffer, a buffer view with its
        mimeType: a GLB's way), or the file `uri`"""
        if uri is not None:
            return self.add("images", {"uri": uri})
        if in_buffer:
            return self.add("images", {"bufferView": self.view(data), "mimeType": mime})
        return self.add("images", {"uri": data_uri(data, mime)})

    def orthographic(self, xmag=1, ymag=1, znear=0.1, zfar=100, name=None):
        c = {"type": "orthographic", "orthographic": {"xmag": xmag, "ymag": ymag, "znear": znear, "zfar": zfar}}
        if name:
            c["name"] = name
        return self.add("cameras", c)

    def perspective(self, yfov, znear, aspect=None, zfar=None, name=None):
        p = {"yfov": yfov, "znear": znear}
        if aspect is not None:
            p["aspectRatio"] = aspect
        if zfar is not None:
            p["zfar"] = zfar
        c = {"type": "perspective", "perspective": p}
        if name:
            c["name"] = name
        return self.add("cameras", c)

    def light(self, type, **fields):
        """a KHR_lights_punctual light (type point, spot or directional; intensity, color, ...)"""
        self.use("KHR_lights_punctual")
        lights = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {}).setdefault("lights", [])
        lights.append(dict({"type": type}, **fields))
        return len(lights) - 1

    def node(self, light=None, **fields):
        """a node (mesh, camera, children, translation, rotation, scale, matrix, ...; light:
        a KHR_lights_punctual light's index)"""
        n = dict(fields)
        if light is not None:
            n.setdefault("extensions", {})["KHR_lights_punctual"] = {"light": light}
        return self.add("nodes", n)

    def scene(self, nodes, default=True, **fields):
        """a scene of these nodes; the first one added is the default ("scene") unless not default"""
        s = self.add("scenes", dict({"nodes": list(nodes)}, **fields))
        if default:
            self.doc.setdefault("scene", s)
        return s

    # ---- shapes -------------------------------------------------------------------------
    def primitive(self, positions, normals=None, indices=None, material=None, index_type=UNSIGNED_INT):
        """a triangle primitive of these flat lists: POSITION (with its bounds), NORMAL and
        indices (of index_type) where given"""
        a = {"POSITION": self.accessor(positions, "VEC3", bounds=True)}
        if normals is not None:
            a["NORMAL"] = self.accessor(normals, "VEC3")
        p = {"attributes": a}
        if indices is not None:
            p["indices"] = self.accessor(indices, "SCALAR", index_type)
        if material is not None:
            p["material"] = material
        return p

    def quad(self, material=None, half=1, z=0, facing=1, uv=True):
        """the primitive of the square [-half, half]^2 at depth z, facing +z (facing -1: -z)
        by its winding and normals: POSITION, NORMAL, TEXCOORD_0 (unless not uv; (0, 0) at
        the top left seen from +z), unsigned-short indices"""
        corners, uvs = [(-1, -1), (1, -1), (1, 1), (-1, 1)], [(0, 1), (1, 1), (1, 0), (0, 0)]
        if facing < 0:
            corners.reverse()
            uvs.reverse()
        a = {"POSITION": self.accessor([c for x, y in corners for c in (x * half, y * half, z)], "VEC3", bounds=True),
             "NORMAL": self.accessor([0, 0, facing] * 4, "VEC3")}
        if uv:
            a["TEXCOORD_0"] = self.accessor([c for p in uvs for c in p], "VEC2")
        p = {"attributes": a, "indices": self.accessor(QUAD_INDICES, "SCALAR", UNSIGNED_SHORT)}
        if material is not None:
            p["material"] = material
        return p

    def quad_view(self, primitive, **node):
        """the scene of the texture tests: the primitive (a quad, say) as a mesh at node 0 (with
        the fields `node`), seen straight on by an orthographic camera at z = 5 (node 1) whose
        view is [-1, 1]^2"""
        self.scene([self.node(mesh=self.mesh(primitive), **node),
                    self.node(camera=self.orthographic(), translation=[0, 0, 5])])

    # ---- files --------------------------------------------------------------------------
    def write(self, path, bin=None, uri=None):
        """the .gltf file; the buffer embedded, or (bin) in the file of that name beside it, or
        (uri) named so and left to the caller (a test of which files gonio reads)"""
        if self.buffer is not None:
            if bin:
                with open(os.path.join(os.path.dirname(path), bin), "wb") as f:
                    f.write(self.data)
            self.doc["buffers"][self.buffer]["uri"] = bin or uri or data_uri(bytes(self.data))
        with open(path, "w") as f:
            json.dump(self.doc, f)
        return path

    def glb(self, path):
        """the .glb file: the JSON chunk, then the buffer as the BIN chunk (both padded to 4)"""
        if self.buffer is not None:
            self.doc["buffers"][self.buffer].pop("uri", None)
        js = json.dumps(self.doc).encode()
        js += b" " * (-len(js) % 4)
        data = bytes(self.data) + b"\0" * (-len(self.data) % 4)
        out = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + (8 + len(data) if self.buffer is not None else 0))
        out += struct.pack("<I4s", len(js), b"JSON") + js
        if self.buffer is not None:
            out += struct.pack("<I4s", len(data), b"BIN\0") + data
        with open(path, "wb") as f:
            f.write(out)
        return path


# ---- shapes ---------------------------------------------------------------------------------
def box(lo, hi):
    """the box [lo, hi]: (positions, normals, indices), 4 corners a face, each face's two
    triangles counter-clockwise seen from outside"""
    p, n, i = [], [], []
    for ax in range(3):
        for sg in (-1, 1):
            u, v = (ax + 1) % 3, (ax + 2) % 3
            b = len(p) // 3
            for a, c in ((0, 0), (1, 0), (1, 1), (0, 1)):
                q = [0, 0, 0]
                q[ax] = hi[ax] if sg > 0 else lo[ax]
                q[u] = (lo[u], hi[u])[a]
                q[v] = (lo[v], hi[v])[c]
                p += q
                nn = [0, 0, 0]
                nn[ax] = sg
                n += nn
            i += [b, b + 1, b + 2, b, b + 2, b + 3] if sg > 0 else [b, b + 2, b + 1, b, b + 3, b + 2]
    return p, n, i


def unindexed(positions, indices):
    """the triangles' corners in index order, as one flat list of positions"""
    return [c for k in indices for c in positions[3 * k:3 * k + 3]]


# ---- images ---------------------------------------------------------------------------------
def png(width, height, pixels, channels=4):
    """an 8-bit PNG (channels 1: grey, 3: RGB, 4: RGBA); pixels(x, y) gives a pixel's
    channel values (from the top left), or pixels is the bytes of every row"""
    if callable(pixels):
        pixels = b"".join(bytes(pixels(x, y)[:channels]) for y in range(height) for x in range(width))
    row = width * channels
    raw = b"".join(b"\0" + pixels[y * row:(y + 1) * row] for y in range(height))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xffffffff)
    colour = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# ---- the command ----------------------------------------------------------------------------
def textured_glb(out, image, fallback=None):
    """a GLB of the quad view textured with `image` (a .webp or .ktx2 file) through
    EXT_texture_webp or KHR_texture_basisu, the image in the binary chunk with its mimeType
    as the extensions' GLB examples have it; with `fallback`, the texture's core source is
    that PNG (also in the chunk) and the extension only used, else it is required"""
    ext, mime = ("EXT_texture_webp", "image/webp") if image.endswith(".webp") else ("KHR_texture_basisu", "image/ktx2")
    g = Gltf(generator="gltf_fixture.py")
    g.use(ext)
    prim = g.quad(material=0)
    with open(image, "rb") as f:
        g.image(f.read(), mime=mime, in_buffer=True)
    texture = {"sampler": g.sampler(mag=NEAREST, min=NEAREST), "extensions": {ext: {"source": 0}}}
    if fallback:
        with open(fallback, "rb") as f:
            texture["source"] = g.image(f.read(), in_buffer=True)
    else:
        g.require(ext)
    g.texture(**texture)
    g.material({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}})
    g.quad_view(prim)
    g.glb(out)


if __name__ == "__main__":
    if len(sys.argv) in (4, 5) and sys.argv[1] == "textured-glb":
        textured_glb(*sys.argv[2:])
    else:
        sys.exit("usage: gltf_fixture.py textured-glb OUT.glb IMAGE [FALLBACK.png]")
