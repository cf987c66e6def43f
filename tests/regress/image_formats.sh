#!/usr/bin/env bash
# image_formats.sh: WebP (EXT_texture_webp) and KTX2 (KHR_texture_basisu) textures. The images
# are made here from one PNG by the formats' own encoders, not by gonio: cwebp (lossless) and
# Basis Universal's encoder (testtool ktx2: ETC1S, UASTC, UASTC with Zstandard). The PNG is
# 16x16 texels in 4x4 blocks of one colour each, R = 40 + 60 i, G = 40 + 60 j for block
# column i and row j from the top, so a block-compressed codec codes each block as one flat
# colour. Each codec's error, against the PNG read by libpng (testtool texels), is bounded by
# what the codec can represent:
#   - lossless WebP: exact;
#   - UASTC: a solid block is UASTC's mode 8, which stores the colour's 8-bit RGBA exactly;
#     one step allowed;
#   - ETC1S: a block is one 5-bit-per-channel base colour (steps of 255/31 = 8.2) plus one
#     intensity modifier shared by R, G and B, so a flat block's channels land within half a
#     step plus what sharing the modifier costs: 6 steps, of which the encoder's codebook
#     clustering may use 2 more; 8 allowed (an image of gradients, which ETC1S cannot
#     code flat, is measured too, with the figures printed).
# The glTF files render a quad that fills an orthographic view with --mode albedo --spp 1
# (the pixel centre): every probed pixel well inside a block must show the PNG's colour,
# sRGB-decoded, within the codec's bound. The fallback image, where there is one, is a flat
# magenta, so a render of the fallback instead of the extension's image fails.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
command -v cwebp >/dev/null || skip_all "cwebp (Debian's webp) is needed to write WebP images"
KTX2=1
if ! "$G" --version | grep -q "Basis Universal [0-9]"; then
    KTX2=0
    echo "  note: this gonio has no Basis Universal ($("$G" --version | sed -n 's/.*no Basis Universal for KTX2 (\(.*\))$/\1/p')): KTX2 decoding and rendering are skipped"
fi
N=48
EXR="python3 $(dirname "$0")/../tool/exrtool.py"

python3 - "$tmp" <<'PY'
import sys
import gltf_fixture as gf
def png(name, w, h, px):
    open(sys.argv[1] + "/" + name, "wb").write(gf.png(w, h, px))
png("blocks.png", 16, 16, lambda i, j: (40 + 60 * (i // 4), 40 + 60 * (j // 4), 0, 255))
png("grad.png", 64, 64, lambda i, j: (4 * i, 4 * j, 2 * (i + j), 255 - 2 * i))
png("fallback.png", 4, 4, lambda i, j: (200, 0, 200, 255))
PY
cwebp -quiet -lossless -exact "$tmp/blocks.png" -o "$tmp/blocks.webp"
cwebp -quiet -lossless -exact "$tmp/grad.png" -o "$tmp/grad.webp"
if [ $KTX2 = 1 ]; then
    for m in etc1s uastc uastc-zstd; do
        "$TESTTOOL" ktx2 $m "$tmp/blocks.png" "$tmp/blocks-$m.ktx2" >/dev/null
        "$TESTTOOL" ktx2 $m "$tmp/grad.png" "$tmp/grad-$m.ktx2" >/dev/null
    done
    "$TESTTOOL" ktx2 etc1s "$tmp/blocks.png" "$tmp/rg-etc1s.ktx2" rg >/dev/null
    "$TESTTOOL" ktx2 uastc "$tmp/blocks.png" "$tmp/rg-uastc.ktx2" rg >/dev/null
fi

# ---- decoded texels against the PNG (image_decode, the loader's decoder) -------------------
T() { check "$1" "$TESTTOOL" texels "${@:2}"; cat "$tmp/out"; }
T "lossless WebP: exact" "$tmp/blocks.webp" "$tmp/blocks.png" RGBA 0 0
T "lossless WebP of gradients and alpha: exact" "$tmp/grad.webp" "$tmp/grad.png" RGBA 0 0
if [ $KTX2 = 1 ]; then
    T "UASTC: flat blocks within 1 step" "$tmp/blocks-uastc.ktx2" "$tmp/blocks.png" RGBA 1 1
    T "UASTC + Zstandard: flat blocks within 1 step" "$tmp/blocks-uastc-zstd.ktx2" "$tmp/blocks.png" RGBA 1 1
    T "ETC1S: flat blocks within 8 steps" "$tmp/blocks-etc1s.ktx2" "$tmp/blocks.png" RGBA 8 8
    # Gradients: UASTC's blocks fit a line through each block's colours (4 steps a texel
    # here, to within its 2-bit-plus weights); ETC1S's one colour plus one shared modifier
    # per block cannot follow R and G rising at once: the bounds are the measured figures'
    # order, to catch a decoder that breaks, not the codecs' guarantees.
    T "UASTC: gradients (figures)" "$tmp/grad-uastc.ktx2" "$tmp/grad.png" RGBA 8 3
    T "UASTC + Zstandard decodes to the same texels as UASTC" "$tmp/grad-uastc-zstd.ktx2" "$tmp/grad.png" RGBA 8 3
    T "ETC1S: gradients (figures)" "$tmp/grad-etc1s.ktx2" "$tmp/grad.png" RGBA 24 6
    T "ETC1S red-green (RRR + GGG slices): green read from the second slice" "$tmp/rg-etc1s.ktx2" "$tmp/blocks.png" RG 8 8
    T "UASTC red-green (RRRG): green read from alpha" "$tmp/rg-uastc.ktx2" "$tmp/blocks.png" RG 1 1
    # The same files with their DFD saying RGB + AAA and RGBA: the data is red-green (green
    # where alpha would be), so read as such their green is their red and fails.
    python3 - "$tmp" <<'PY'
import struct, sys
d = sys.argv[1]
for name, ids in (("rg-etc1s", (0, 15)), ("rg-uastc", (3,))):
    b = bytearray(open("%s/%s.ktx2" % (d, name), "rb").read())
    dfd = struct.unpack_from("<I", b, 48)[0]
    for k, c in enumerate(ids):
        b[dfd + 28 + 16 * k + 3] = (b[dfd + 28 + 16 * k + 3] & 0xF0) | c
    open("%s/%s-as-rgba.ktx2" % (d, name), "wb").write(bytes(b))
PY
    check_fails "ETC1S red-green data read as RGB + alpha: green is wrong" 1 \
        "$TESTTOOL" texels "$tmp/rg-etc1s-as-rgba.ktx2" "$tmp/blocks.png" RG 8 8
    check_fails "UASTC red-green data read as RGBA: green is wrong" 1 \
        "$TESTTOOL" texels "$tmp/rg-uastc-as-rgba.ktx2" "$tmp/blocks.png" RG 1 1
fi

# ---- glTF files that use the extensions ------------------------------------------------------
# gen.py OUT.gltf JSON: the quad view (gltf_fixture), its material's base colour the texture
# (NEAREST filtering); JSON: images (file names), texture (the texture object), used, required
cat >"$tmp/gen.py" <<'PY'
import json, sys
import gltf_fixture as gf
out, opt = sys.argv[1], json.loads(sys.argv[2])
g = gf.Gltf(generator="image_formats.sh")
g.use(*opt.get("used", []))
g.require(*opt.get("required", []))
for u in opt["images"]:
    g.image(uri=u)
g.texture(**dict(opt["texture"], sampler=g.sampler(gf.NEAREST, gf.NEAREST)))
g.quad_view(g.quad(g.material({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}})))
g.write(out)
PY

# probe.py IMAGE.exr TOL: every 3rd pixel well inside a block has the block's colour,
# sRGB-decoded, within TOL 8-bit steps.
cat >"$tmp/probe.py" <<'PY'
import math, sys
sys.path.insert(0, sys.argv[3])
import exrtool
_, ch = exrtool.read(sys.argv[1])
tol, n = float(sys.argv[2]), int(sys.argv[4])
def lin(c):
    c = min(max(c, 0), 255) / 255
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
bad = checked = 0
for py in range(1, n, 3):
    for px in range(1, n, 3):
        bx, by = (px + 0.5) / n * 4, (py + 0.5) / n * 4  # in blocks
        if min(abs(bx - round(bx)), abs(by - round(by))) < 0.1:
            continue
        i, j = int(bx), int(by)
        checked += 1
        for k, c in (("R", 40 + 60 * i), ("G", 40 + 60 * j)):
            got = ch[k][1][py * n + px]
            if not lin(c - tol) - 1e-3 <= got <= lin(c + tol) + 1e-3:
                bad += 1
                if bad <= 5: print("pixel (%d, %d) %s: got %.4f, want block (%d, %d): %.4f" % (px, py, k, got, i, j, lin(c)))
print("%d pixels checked, %d values wrong" % (checked, bad))
sys.exit(1 if bad or checked < 100 else 0)
PY

scene() { python3 "$tmp/gen.py" "$tmp/$1.gltf" "$2"; }
# R NAME: renders $tmp/NAME.gltf's albedo to $tmp/NAME.exr. The script's renders are queued
# instead (lib.sh: queue) and run in one batch (below); the checks of each read its status,
# output ($tmp/last) and image. QR NAME [FILE]: queues R's render (of FILE).
albedo=(--mode albedo --spp 1 --size ${N}x$N --quiet --compression none)
R() { "$G" render "$tmp/$1.gltf" "${albedo[@]}" -o "$tmp/$1.exr"; }
QR() { queue "$1" render "${2:-$tmp/$1.gltf}" "${albedo[@]}" -o "$tmp/$1.exr"; }
# case NAME TOL DESCRIPTION JSON: write, queue; once the queue has run: renders (no warning), probe
case_() {
    scene "$1" "$4"
    QR "$1"
    after_queue render_checks "$@"
}
render_checks() {
    check_queued "$3: renders" 0 "$1"
    check "$3: no warning" test ! -s "$tmp/last"
    check "$3: the image's texels" python3 "$tmp/probe.py" "$tmp/$1.exr" "$2" "$(dirname "$0")/../tool" $N
}
WEBP='["EXT_texture_webp"]'
BASISU='["KHR_texture_basisu"]'
case_ webp_fallback 0 "WebP with a PNG fallback, extension used" \
    "{\"images\": [\"fallback.png\", \"blocks.webp\"], \"texture\": {\"source\": 0, \"extensions\": {\"EXT_texture_webp\": {\"source\": 1}}}, \"used\": $WEBP}"
case_ webp_required 0 "WebP without a fallback, extension required" \
    "{\"images\": [\"blocks.webp\"], \"texture\": {\"extensions\": {\"EXT_texture_webp\": {\"source\": 0}}}, \"used\": $WEBP, \"required\": $WEBP}"
if [ $KTX2 = 1 ]; then
    case_ etc1s_fallback 8 "KTX2 ETC1S with a PNG fallback, extension used" \
        "{\"images\": [\"fallback.png\", \"blocks-etc1s.ktx2\"], \"texture\": {\"source\": 0, \"extensions\": {\"KHR_texture_basisu\": {\"source\": 1}}}, \"used\": $BASISU}"
    case_ uastc_required 1 "KTX2 UASTC without a fallback, extension required" \
        "{\"images\": [\"blocks-uastc.ktx2\"], \"texture\": {\"extensions\": {\"KHR_texture_basisu\": {\"source\": 0}}}, \"used\": $BASISU, \"required\": $BASISU}"
    case_ zstd_required 1 "KTX2 UASTC + Zstandard without a fallback, extension required" \
        "{\"images\": [\"blocks-uastc-zstd.ktx2\"], \"texture\": {\"extensions\": {\"KHR_texture_basisu\": {\"source\": 0}}}, \"used\": $BASISU, \"required\": $BASISU}"
    after_queue check "gonio info: the images' formats" sh -c "'$G' info '$tmp/etc1s_fallback.gltf' | grep -q '^image formats  1 PNG, 1 KTX2$'"
else
    scene needs_basisu "{\"images\": [\"fallback.png\"], \"texture\": {\"extensions\": {\"KHR_texture_basisu\": {\"source\": 0}}}, \"used\": $BASISU, \"required\": $BASISU}"
    check_fails "without Basis Universal, a file requiring KHR_texture_basisu is refused" 1 R needs_basisu
    check "... saying why" grep -q "needs_basisu.gltf: requires unsupported extension KHR_texture_basisu (this gonio was built without Basis Universal" "$tmp/last"
fi

# Images in a GLB's binary chunk, with their mimeType (decoded once the buffer views are
# checked, where files named by a uri are decoded as tinygltf reads them).
glb_case() { # glb_case NAME TOL DESCRIPTION IMAGE [FALLBACK]: write, queue, then case_'s checks
    python3 -m gltf_fixture textured-glb "$tmp/$1.glb" "${@:4}"
    QR "$1" "$tmp/$1.glb"
    after_queue render_checks "$@"
}
glb_case glb_webp 0 "GLB: WebP in the binary chunk, extension required" "$tmp/blocks.webp"
if [ $KTX2 = 1 ]; then
    glb_case glb_ktx2 1 "GLB: KTX2 UASTC + Zstandard in the binary chunk, a PNG fallback" "$tmp/blocks-uastc-zstd.ktx2" "$tmp/fallback.png"
fi

# ---- the damaged images' renders' scenes (their checks below), and the batch ---------------
head -c $(($(wc -c <"$tmp/grad.webp") / 2)) "$tmp/grad.webp" >"$tmp/trunc.webp"
if [ $KTX2 = 1 ]; then
    head -c 150 "$tmp/blocks-uastc-zstd.ktx2" >"$tmp/trunc.ktx2"
else
    python3 -c "import sys; sys.stdout.buffer.write(b'\xabKTX 20\xbb\r\n\x1a\n' + bytes(100))" >"$tmp/trunc.ktx2"
fi
scene trunc_fallback "{\"images\": [\"blocks.png\", \"trunc.ktx2\"], \"texture\": {\"source\": 0, \"extensions\": {\"KHR_texture_basisu\": {\"source\": 1}}}, \"used\": $BASISU}"
QR trunc_fallback
# a missing PNG a texture uses (gonio info, below); one no texture uses; one only a material
# the scene does not draw uses
scene missing_png '{"images": ["nowhere.png"], "texture": {"source": 0}}'
scene unused_png '{"images": ["fallback.png", "nowhere.png"], "texture": {"source": 0}}'
python3 - "$tmp/missing_png.gltf" "$tmp/undrawn_png.gltf" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["images"] = [{"uri": "fallback.png"}, {"uri": "nowhere.png"}]
d["textures"].append({"source": 1})
d["materials"].append({"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}})
json.dump(d, open(sys.argv[2], "w"))
PY
for f in unused_png undrawn_png; do
    queue $f render "$tmp/$f.gltf" --spp 1 --size 8x8 --quiet -o "$tmp/$f.exr"
done
if [ $KTX2 = 1 ]; then # both extensions, the KTX2 image damaged, no core image
    scene both_ext "{\"images\": [\"blocks.webp\", \"trunc.ktx2\"], \"texture\": {\"extensions\": {\"KHR_texture_basisu\": {\"source\": 1}, \"EXT_texture_webp\": {\"source\": 0}}}, \"used\": [\"KHR_texture_basisu\", \"EXT_texture_webp\"]}"
    QR both_ext
fi
run_queue

# ---- damaged images: a clear message naming the file, the image and the problem ------------
# (gonio info loads a scene as render does, and says the same, without a device)
# (trunc_fallback's status unchecked, as ever: what it says, in its log)
check "truncated KTX2 with a fallback: renders the fallback" python3 "$tmp/probe.py" "$tmp/trunc_fallback.exr" 0 "$(dirname "$0")/../tool" $N
check "... saying which image of which file, and why" grep -q "trunc_fallback.gltf: image 1 trunc.ktx2: KTX2: " "$tmp/queue/trunc_fallback.log"
check "... and that the fallback is used" grep -q "texture 0: its KHR_texture_basisu image 1 is unusable; its fallback, image 0, is used" "$tmp/queue/trunc_fallback.log"
scene trunc_webp "{\"images\": [\"trunc.webp\"], \"texture\": {\"extensions\": {\"EXT_texture_webp\": {\"source\": 0}}}, \"used\": $WEBP, \"required\": $WEBP}"
check_fails "truncated WebP a texture uses: an error" 1 "$G" render "$tmp/trunc_webp.gltf" --spp 1 --size 8x8 --quiet -o "$tmp/trunc_webp.exr"
check "... naming the file, the material, the texture, the image and the problem" grep -q "error: .*trunc_webp.gltf: material 0: baseColorTexture: texture 0: image 0 trunc.webp: WebP: libwebp cannot decode the 64x64 image (corrupt or truncated data)" "$tmp/last"
check "... and no output" test ! -e "$tmp/trunc_webp.exr"
printf 'RIFF\x20\0\0\0WEBPVP8 ' >"$tmp/junk.webp"
scene junk_webp "{\"images\": [\"junk.webp\"], \"texture\": {\"extensions\": {\"EXT_texture_webp\": {\"source\": 0}}}, \"used\": $WEBP}"
check_fails "a WebP header and no image: an error" 1 "$G" info "$tmp/junk_webp.gltf"
check "... the problem named" grep -q "error: .*junk_webp.gltf: material 0: baseColorTexture: texture 0: image 0 junk.webp: WebP: .*" "$tmp/last"
# The core formats alike: a PNG a texture uses that is missing is an error; an image no
# texture uses is only a warning, and the file renders.
check_fails "a missing PNG a texture uses: an error" 1 "$G" info "$tmp/missing_png.gltf"
check "... naming the material, the texture and the image" grep -q "error: .*missing_png.gltf: material 0: baseColorTexture: texture 0: image 0 nowhere.png: file missing or unreadable" "$tmp/last"
check_queued "an unreadable image no texture uses: renders" 0 unused_png
check "... with a warning saying so" grep -q "warning: .*unused_png.gltf: image 1 nowhere.png: file missing or unreadable; no texture draws it" "$tmp/queue/unused_png.log"
# A texture only a material the scene does not draw uses: a warning too.
check_queued "a broken texture only an undrawn material uses: renders" 0 undrawn_png
check "... with a warning saying so" grep -q "warning: .*undrawn_png.gltf: texture 1: image 1 nowhere.png: file missing or unreadable; no material the scene draws uses it" "$tmp/queue/undrawn_png.log"
if [ $KTX2 = 1 ]; then
    # Both extensions, the KTX2 image damaged and no core image: the WebP one is drawn.
    check_queued "a damaged KTX2 beside a WebP, no core image: renders" 0 both_ext
    check "... the WebP's texels" python3 "$tmp/probe.py" "$tmp/both_ext.exr" 0 "$(dirname "$0")/../tool" $N
fi
if [ $KTX2 = 1 ]; then
    # Every kind of damage the KTX2 checks name, each in a copy of a good file.
    python3 - "$tmp" <<'PY'
import struct, sys
d = sys.argv[1]
good = open(d + "/blocks-etc1s.ktx2", "rb").read()
def put(name, off, fmt, v):
    b = bytearray(good); struct.pack_into(fmt, b, off, v); open(d + "/" + name, "wb").write(bytes(b))
put("vkformat.ktx2", 12, "<I", 37)        # VK_FORMAT_R8G8B8A8_UNORM: not Basis Universal
put("cube.ktx2", 36, "<I", 6)             # faceCount 6
put("levels.ktx2", 40, "<I", 9)           # levelCount 9 for a 16x16 image
put("scheme.ktx2", 44, "<I", 3)           # supercompression 3
put("level0.ktx2", 80, "<Q", 1 << 62)     # level 0's offset far past the end
put("sgd.ktx2", 72, "<Q", (1 << 64) - 1)  # global data that wraps around
put("kvd.ktx2", 60, "<I", (1 << 32) - 14)  # key/value data that wraps around in 32 bits (the fuzzer's find)
put("huge.ktx2", 20, "<Q", 65536 | 65536 << 32) # width and height 65536: 2^32 texels declared
b = bytearray(good); b[len(b) // 2:] = bytes(len(b) - len(b) // 2); open(d + "/zeroed.ktx2", "wb").write(bytes(b))
u = open(d + "/blocks-uastc.ktx2", "rb").read()  # UASTC's level moved one byte on (the fuzzer's find)
off = struct.unpack_from("<Q", u, 80)[0]
b = bytearray(u[:off] + b"\0" + u[off:]); struct.pack_into("<Q", b, 80, off + 1); open(d + "/misaligned.ktx2", "wb").write(bytes(b))
PY
    for f in vkformat:"vkFormat 37" cube:"cube map" levels:"levelCount 9" scheme:"supercompression scheme 3" \
        level0:"level 0's" sgd:"BasisLZ global data" zeroed:"Basis Universal cannot" misaligned:"not a multiple of 16" \
        kvd:"key/value data"; do
        k=${f%%:*} want=${f#*:}
        scene "bad_$k" "{\"images\": [\"$k.ktx2\"], \"texture\": {\"extensions\": {\"KHR_texture_basisu\": {\"source\": 0}}}, \"used\": $BASISU, \"required\": $BASISU}"
        check_fails "KTX2 $k: an error" 1 "$G" info "$tmp/bad_$k.gltf"
        check "... '$want' named, with the file and image" grep -q "error: .*bad_$k.gltf: material 0: baseColorTexture: texture 0: image 0 $k.ktx2: KTX2: .*$want.*" "$tmp/last"
    done
    # A huge declared size is refused by the texel limit before anything is allocated (a
    # 65536x65536 RGBA8 buffer would be 16 GiB): an image larger than all a scene's images may
    # be is unusable, and so a texture's fallback is used where it has one.
    scene huge "{\"images\": [\"huge.ktx2\"], \"texture\": {\"extensions\": {\"KHR_texture_basisu\": {\"source\": 0}}}, \"used\": $BASISU, \"required\": $BASISU}"
    check_fails "KTX2 declaring 65536x65536: refused" 1 "$G" render "$tmp/huge.gltf" --mode albedo --spp 1 --size 8x8 --quiet -o "$tmp/huge.exr"
    check "... by the texel limit, with the numbers" grep -q "huge.gltf: .*image 0 huge.ktx2: KTX2: it declares 65536x65536, 4294967296 texels, more than the 268435456 a scene's images may have" "$tmp/last"
    check "... and no output" test ! -e "$tmp/huge.exr"
    scene huge_fb "{\"images\": [\"huge.ktx2\", \"fallback.png\"], \"texture\": {\"source\": 1, \"extensions\": {\"KHR_texture_basisu\": {\"source\": 0}}}, \"used\": $BASISU}"
    check "with a PNG fallback it loads" sh -c '"$0" info "$1" >/dev/null 2>"$2"' "$G" "$tmp/huge_fb.gltf" "$tmp/huge_fb.err"
    check "... saying the fallback is used" grep -q "its KHR_texture_basisu image 0 is unusable; its fallback, image 1, is used instead" "$tmp/huge_fb.err"
fi
# WebP sizes stop at 16383: two declared at the most pass the limit together. The lossless
# header's 14-bit width and height fields are set, the data left as it is.
python3 - "$tmp" <<'PY'
import struct, sys
d = sys.argv[1]
b = bytearray(open(d + "/blocks.webp", "rb").read())
assert b[12:16] == b"VP8L" and b[20] == 0x2f, "cwebp wrote no simple lossless header"
bits = struct.unpack_from("<I", b, 21)[0]
bits = (bits & ~((1 << 28) - 1)) | 16382 | 16382 << 14
struct.pack_into("<I", b, 21, bits)
open(d + "/huge.webp", "wb").write(bytes(b))
open(d + "/huge2.webp", "wb").write(bytes(b) + b"\0\0")  # other bytes: not one image decoded twice
PY
scene huge_webp "{\"images\": [\"huge.webp\", \"huge2.webp\"], \"texture\": {\"extensions\": {\"EXT_texture_webp\": {\"source\": 0}}}, \"used\": $WEBP}"
check_fails "two WebPs declaring 16383x16383: refused" 1 "$G" info "$tmp/huge_webp.gltf"
check "... by the texel limit, with the numbers" grep -q "images too large: 536805378 texels with image 1 (16383x16383)" "$tmp/last"

# ---- the JSON checks of the extensions' source ----------------------------------------------
J() { # J NAME TEXTURE-JSON MESSAGE
    scene "$1" "{\"images\": [\"blocks.webp\"], \"texture\": $2, \"used\": $WEBP}"
    check_fails "$1: refused" 1 "$G" info "$tmp/$1.gltf"
    check "$1: the JSON path and the problem" grep -q "$1.gltf: $3" "$tmp/last"
}
J fractional '{"extensions": {"EXT_texture_webp": {"source": 0.5}}}' "textures\[0\].extensions.EXT_texture_webp.source: 0.5 is not an integer index"
J missing '{"extensions": {"EXT_texture_webp": {}}}' "textures\[0\].extensions.EXT_texture_webp.source: missing (required)"
J nosuch '{"extensions": {"KHR_texture_basisu": {"source": 3}}}' "textures\[0\].extensions.KHR_texture_basisu.source: 3 does not exist (images has 1 entry)"
J negative '{"source": 0, "extensions": {"EXT_texture_webp": {"source": -1}}}' "textures\[0\].extensions.EXT_texture_webp.source: -1 is not a valid index (negative)"
finish
