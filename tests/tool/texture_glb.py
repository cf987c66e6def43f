#!/usr/bin/env python3
"""texture_glb.py OUT.glb IMAGE [FALLBACK.png]: a GLB whose one quad is textured with IMAGE
(a .webp or .ktx2 file) through EXT_texture_webp or KHR_texture_basisu, the image stored in
the binary chunk with its mimeType, as the extensions' GLB examples have it. With FALLBACK,
the texture's core source is that PNG (also in the chunk) and the extension only used;
without, the extension is required. The quad and camera are image_formats.sh's: [-1, 1]^2
filling an orthographic view, uv (0, 0) at its top left. Written here, not by gonio: the
tests' and the fuzzer's seeds of images in buffer views."""
import json
import struct
import sys

out, image = sys.argv[1], sys.argv[2]
fallback = sys.argv[3] if len(sys.argv) > 3 else None
ext, mime = ("EXT_texture_webp", "image/webp") if image.endswith(".webp") else ("KHR_texture_basisu", "image/ktx2")

blob, views = b"", []


def add(data):
    global blob
    while len(blob) % 4:
        blob += b"\0"
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
    blob += data
    return len(views) - 1


pos = add(struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0))
nrm = add(struct.pack("<12f", *[0, 0, 1] * 4))
uv = add(struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0))
idx = add(struct.pack("<6H", 0, 1, 2, 0, 2, 3))
images = [{"bufferView": add(open(image, "rb").read()), "mimeType": mime}]
texture = {"sampler": 0, "extensions": {ext: {"source": 0}}}
if fallback:
    images.append({"bufferView": add(open(fallback, "rb").read()), "mimeType": "image/png"})
    texture["source"] = 1
doc = {
    "asset": {"version": "2.0", "generator": "texture_glb.py"},
    "extensionsUsed": [ext],
    "buffers": [{"byteLength": len(blob)}],
    "bufferViews": views,
    "accessors": [
        {"bufferView": pos, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
        {"bufferView": nrm, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": uv, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": idx, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    "images": images,
    "samplers": [{"magFilter": 9728, "minFilter": 9728}],
    "textures": [texture],
    "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
                                "material": 0}]}],
    "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 100}}],
    "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}],
    "scenes": [{"nodes": [0, 1]}], "scene": 0,
}
if not fallback:
    doc["extensionsRequired"] = [ext]
js = json.dumps(doc).encode()
js += b" " * (-len(js) % 4)
blob += b"\0" * (-len(blob) % 4)
glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(blob))
glb += struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(blob), b"BIN\0") + blob
open(out, "wb").write(glb)
