#!/usr/bin/env bash
# slots.sh: the texture slots of KHR_materials_specular (specularTexture, specularColorTexture)
# and _transmission (transmissionTexture) in path renders. Each spec says the texture's
# channel (A, RGB in sRGB, R) scales its factor; so a quad whose texture is 0 on its left half
# and 1 (255) on its right must render, half by half, as the same quad without the texture
# and that factor times 0, and times 1: two renders made by another path (no texture at all).
# The quad is seen straight on by an orthographic camera, under a constant environment;
# the renders of factor 0 and 1 must differ, or the check proves nothing.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
W=16 H=8 # a texel a half: 8 pixel columns each

# gen.py OUT.gltf EXT FACTOR-KEY FACTOR-JSON TEXTURE-KEY|-: the quad, its material's base a
# grey dielectric, with EXT's FACTOR and (unless -) its texture TEXTURE-KEY: a 2x1 image,
# left texel all 0, right all 255, NEAREST filtering.
cat >"$tmp/gen.py" <<'PY'
import base64, json, struct, sys, zlib
out, ext, key, value, tex = sys.argv[1], sys.argv[2], sys.argv[3], json.loads(sys.argv[4]), sys.argv[5]
pos = [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]
uv = [0, 1, 1, 1, 1, 0, 0, 0]
blob = struct.pack("<12f", *pos) + struct.pack("<12f", *[0, 0, 1] * 4) + struct.pack("<8f", *uv) + \
       struct.pack("<6H", 0, 1, 2, 0, 2, 3)
views = [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48},
         {"buffer": 0, "byteOffset": 96, "byteLength": 32}, {"buffer": 0, "byteOffset": 128, "byteLength": 12}]
accs = [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]
rows = b"\0" + bytes([0, 0, 0, 0, 255, 255, 255, 255])
def chunk(t, d): return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 1, 8, 6, 0, 0, 0)) + \
      chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
e = {key: value}
if tex != "-":
    e[tex] = {"index": 0}
doc = {
    "asset": {"version": "2.0"}, "extensionsUsed": [ext],
    "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": views, "accessors": accs,
    "images": [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}],
    "samplers": [{"magFilter": 9728, "minFilter": 9728}], "textures": [{"source": 0, "sampler": 0}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0,
                                            "roughnessFactor": 0.4}, "extensions": {ext: e}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
                                "material": 0}]}],
    "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 100}}],
    "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}], "scenes": [{"nodes": [0, 1]}], "scene": 0,
}
json.dump(doc, open(out, "w"))
PY

# halves.py TEXTURED.exr ZERO.exr ONE.exr: the textured render's left half is ZERO's and its
# right half ONE's, pixel by pixel (but the two columns at the seam), and ZERO and ONE differ.
cat >"$tmp/halves.py" <<'PY'
import sys
sys.path.insert(0, sys.argv[4])
import exrtool
def rgb(path):
    _, ch = exrtool.read(path)
    return [ch[c][1] for c in "RGB"]
t, z, o = rgb(sys.argv[1]), rgb(sys.argv[2]), rgb(sys.argv[3])
w = int(sys.argv[5])
bad = differ = 0
for c in range(3):
    for i, v in enumerate(t[c]):
        x = i % w
        if x in (w // 2 - 1, w // 2):
            continue
        want = z[c][i] if x < w // 2 else o[c][i]
        if abs(v - want) > 1e-4 * max(1.0, abs(want)):
            bad += 1
            if bad <= 5: print("pixel %d channel %d: %.6f, not %.6f" % (i, c, v, want))
        differ += abs(z[c][i] - o[c][i]) > 0.01
print("%d values wrong, %d differ between factor 0 and 1" % (bad, differ))
sys.exit(1 if bad or differ == 0 else 0)
PY

# slot NAME EXT FACTOR-KEY FACTOR-AT-1 FACTOR-AT-0 TEXTURE-KEY: writes the three scenes and
# queues their renders (lib.sh: queue; the script's renders run in one batch); once the queue
# has run, the checks.
slot() {
    python3 "$tmp/gen.py" "$tmp/$1-tex.gltf" "$2" "$3" "$4" "$6" &&
        python3 "$tmp/gen.py" "$tmp/$1-one.gltf" "$2" "$3" "$4" - &&
        python3 "$tmp/gen.py" "$tmp/$1-zero.gltf" "$2" "$3" "$5" - || { fail "$1: scenes"; return; }
    local v
    for v in tex one zero; do
        queue "$1-$v" render "$tmp/$1-$v.gltf" --spp 4 --size ${W}x$H --env 1 --compression none --quiet -o "$tmp/$1-$v.exr"
    done
    after_queue slot_checks "$@"
}
# all_ok ID...: every queued line gave 0 (the first that did not: its output)
all_ok() {
    local id
    for id; do queued_ok "$id" || { echo "$id:"; cat "$tmp/last"; return 1; }; done
}
slot_checks() {
    check "$1: renders" all_ok $1-tex $1-one $1-zero
    check "$1: $6 scales $3 texel by texel" python3 "$tmp/halves.py" "$tmp/$1-tex.exr" "$tmp/$1-zero.exr" \
        "$tmp/$1-one.exr" "$(dirname "$0")/../tool" $W
}
slot specular KHR_materials_specular specularFactor 1 0 specularTexture
slot specular-color KHR_materials_specular specularColorFactor "[1, 1, 1]" "[0, 0, 0]" specularColorTexture
slot transmission KHR_materials_transmission transmissionFactor 1 0 transmissionTexture
run_queue
finish
