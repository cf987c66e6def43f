#!/usr/bin/env bash
# textures.sh: what a material's texture reads where (KHR_texture_transform, TEXCOORD_1,
# samplers' wrap and filter modes) and KHR_mesh_quantization's integer attributes. The
# scenes are glTF JSON written here by Python, not by gonio: a quad [-1, 1]^2 seen straight
# on by an orthographic camera that fills the image with it, textured with a 4x4 image of
# distinct texels and a NEAREST sampler, rendered with --mode albedo --spp 1 (the first
# sample is the pixel centre). For every probed pixel the expected texel comes from the
# specs' formulas, computed here: the spec's matrix T R S on the pixel's uv, the sampler's
# wrap of the texel index, the sRGB decode of its bytes.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
N=48 # image size: 12 pixels a texel at uv scale 1

# gen.py OUT.gltf JSON-OPTIONS: the quad view (gltf_fixture), textured; options: wrap [S, T],
# mag and min (the filters), tt (the KHR_texture_transform object), texcoord (the
# reference's), uv0/uv1 (the uv of the quad's top-left and bottom-right corners per set, or
# null), quant (store attributes quantized), declare_quant, normal (the quad's normal, for
# the quantization check in --mode normal).
cat >"$tmp/gen.py" <<'PY'
import json, sys
import gltf_fixture as gf
out, opt = sys.argv[1], json.loads(sys.argv[2])
def corners(a, b):  # uv at the quad's corners (-1,-1), (1,-1), (1,1), (-1,1); a top-left, b bottom-right
    return [a[0], b[1], b[0], b[1], b[0], a[1], a[0], a[1]]
nrm = opt.get("normal", [0, 0, 1]) * 4
q = opt.get("quant", False)
g = gf.Gltf(generator="textures.sh")
attrs = {}
if q:  # POSITION as unsigned shorts 0..2 (the node moves them back by -1), NORMAL as bytes
    attrs["POSITION"] = g.accessor([int(v + 1) if i % 3 < 2 else 0 for i, v in enumerate(gf.QUAD_POSITIONS)],
                                   "VEC3", gf.UNSIGNED_SHORT, bounds=True)
    attrs["NORMAL"] = g.accessor(sum([[round(c * 127) for c in nrm[0:3]] + [0] for _ in range(4)], []),
                                 "VEC3", gf.BYTE, count=4, stride=4, normalized=True)
else:
    attrs["POSITION"] = g.accessor(gf.QUAD_POSITIONS, "VEC3", bounds=True)
    attrs["NORMAL"] = g.accessor(nrm, "VEC3")
for s in (0, 1):
    c = opt.get("uv%d" % s)
    if c is None: continue
    uv = corners(*c)
    if q:  # signed shorts, not normalized: the corners are integers here
        attrs["TEXCOORD_%d" % s] = g.accessor([int(v) for v in uv], "VEC2", gf.SHORT)
    else:
        attrs["TEXCOORD_%d" % s] = g.accessor(uv, "VEC2")
ind = g.accessor(gf.QUAD_INDICES, "SCALAR", gf.UNSIGNED_SHORT)
# the 4x4 RGBA image: texel (i, j) (column, row from the top) has R = 40 + 60 i, G = 40 + 60 j
image = g.image(gf.png(4, 4, lambda i, j: (40 + 60 * i, 40 + 60 * j, 0, 255)))
ref = {"index": g.texture(image, g.sampler(opt.get("mag", gf.NEAREST), opt.get("min"), opt.get("wrap", [gf.REPEAT] * 2)))}
if "texcoord" in opt: ref["texCoord"] = opt["texcoord"]
if "tt" in opt: g.extend(ref, "KHR_texture_transform", opt["tt"])
if opt.get("declare_quant", q): g.use("KHR_mesh_quantization")
material = g.material({"pbrMetallicRoughness": {"baseColorTexture": ref, "metallicFactor": 0}})
g.quad_view({"attributes": attrs, "indices": ind, "material": material}, translation=[-1, -1, 0] if q else [0, 0, 0])
g.write(out)
PY

# probe.py IMAGE.exr JSON-OPTIONS: every 3rd pixel whose centre lies well inside one texel
# (the expected one) must have that texel's linear colour in R and G.
cat >"$tmp/probe.py" <<'PY'
import json, math, subprocess, sys
img, opt, tool, n = sys.argv[1], json.loads(sys.argv[2]), sys.argv[3], int(sys.argv[4])
s = opt.get("texcoord", 0)
tt = opt.get("tt", {})
s = tt.get("texCoord", s)
(a, b) = opt["uv%d" % s]
ox, oy = tt.get("offset", [0, 0]); sx, sy = tt.get("scale", [1, 1]); r = tt.get("rotation", 0)
def transform(u, v):  # KHR_texture_transform: T * R * S, R = [cos sin; -sin cos]
    u, v = sx * u, sy * v
    return math.cos(r) * u + math.sin(r) * v + ox, -math.sin(r) * u + math.cos(r) * v + oy
def wrap(i, mode):
    if mode == 33071: return min(max(i, 0), 3)
    if mode == 33648:
        m = i % 8
        return m if m < 4 else 7 - m
    return i % 4
def lin(c):
    c /= 255
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
wrap_st = opt.get("wrap", [10497, 10497])
probes = []  # (px, py, expected texel i, j)
for py in range(1, n, 3):
    for px in range(1, n, 3):
        fx, fy = (px + 0.5) / n, (py + 0.5) / n  # 0..1 across the quad, from its top-left
        u0, v0 = transform(a[0] + fx * (b[0] - a[0]), a[1] + fy * (b[1] - a[1]))
        tx, ty = u0 * 4, v0 * 4
        if min(abs(tx - round(tx)), abs(ty - round(ty))) < 0.05:
            continue  # near a texel edge
        probes.append((px, py, wrap(math.floor(tx), wrap_st[0]), wrap(math.floor(ty), wrap_st[1])))
# every probed pixel's R, then G, in one read of the image each
xy = [str(c) for p in probes for c in p[:2]]
values = {ch: [float(v) for v in subprocess.check_output([tool, "at", img, ch] + xy).split()] for ch in "RG"} if probes else {}
bad = checked = 0
for k, (px, py, i, j) in enumerate(probes):
    want = (lin(40 + 60 * i), lin(40 + 60 * j))
    got = [values["R"][k], values["G"][k]]
    checked += 1
    if abs(got[0] - want[0]) > 1e-3 or abs(got[1] - want[1]) > 1e-3:
        bad += 1
        if bad <= 5: print("pixel (%d, %d): got %.4f %.4f, want texel (%d, %d) = %.4f %.4f" % (px, py, *got, i, j, *want))
print("%d pixels checked, %d wrong" % (checked, bad))
sys.exit(1 if bad or checked < 50 else 0)
PY

scene() { python3 "$tmp/gen.py" "$tmp/$1.gltf" "$2"; }
# case NAME OPTIONS DESCRIPTION: write the scene and queue its render (lib.sh, queue); once
# the queue has run, probe it.
case_() {
    scene "$1" "$2" || { fail "$3: the scene"; return; }
    queue "$1" render "$tmp/$1.gltf" --mode albedo --spp 1 --size ${N}x$N --quiet -o "$tmp/$1.exr"
    after_queue case_checks "$@"
}
case_checks() {
    check_queued "$3: renders" 0 "$1" &&
        check "$3: texels where the spec puts them" python3 "$tmp/probe.py" "$tmp/$1.exr" "$2" "$TESTTOOL" $N
}

UV='"uv0": [[0, 0], [1, 1]]'
WIDE='"uv0": [[-1, -1], [2, 2]]' # three tiles across: what wrap modes do outside [0, 1]
case_ plain "{$UV}" "no transform"
case_ repeat "{$WIDE, \"wrap\": [10497, 10497]}" "REPEAT outside [0,1]"
case_ mirror "{$WIDE, \"wrap\": [33648, 33648]}" "MIRRORED_REPEAT outside [0,1]"
case_ clamp "{$WIDE, \"wrap\": [33071, 33071]}" "CLAMP_TO_EDGE outside [0,1]"
case_ mixed "{$WIDE, \"wrap\": [33071, 33648]}" "CLAMP S, MIRROR T"
case_ offset "{$UV, \"tt\": {\"offset\": [0.25, -0.5]}}" "transform offset"
case_ scale "{$UV, \"tt\": {\"scale\": [2, 0.5]}}" "transform scale"
case_ rotation "{$UV, \"tt\": {\"rotation\": 0.5235988}}" "transform rotation (30 degrees)"
case_ all "{$UV, \"wrap\": [33648, 10497], \"tt\": {\"offset\": [0.3, 0.1], \"rotation\": -1.1, \"scale\": [1.5, 0.75]}}" \
    "transform offset, rotation and scale, mirrored S"
# TEXCOORD_1: set 0 puts the whole quad in texel (0, 0); set 1 maps it as above
UV01='"uv0": [[0.01, 0.01], [0.02, 0.02]], "uv1": [[0, 0], [1, 1]]'
case_ uv1 "{$UV01, \"texcoord\": 1}" "texCoord 1 reads TEXCOORD_1"
case_ uv1tt "{$UV01, \"texcoord\": 0, \"tt\": {\"texCoord\": 1, \"offset\": [0.5, 0]}}" \
    "KHR_texture_transform's texCoord overrides the reference's"

# The scenes below render in the same batch (lib.sh, queue), their checks after it.
# R NAME [MODE [SIZE]]: queues the render of $tmp/NAME.gltf (--mode albedo, N x N by default).
R() { queue "$1" render "$tmp/$1.gltf" --mode "${2:-albedo}" --spp 1 --size "${3:-${N}x$N}" --quiet -o "$tmp/$1.exr"; }
scene uv1none "{\"uv0\": [[0, 0], [1, 1]], \"texcoord\": 2}" && R uv1none albedo 8x8
# Filters: bilinear (magFilter LINEAR) blends the two nearest texel centres linearly:
# along row 30, pixel x's centre lies at p = (x + 0.5) / 12 - 0.5 texel centres, so R is
# (1 - f) texel floor(p) + f the next, f = p - floor(p) (sRGB decoded before blending).
# Without magFilter, minFilter NEAREST_MIPMAP_LINEAR's NEAREST is used.
scene linear "{$UV, \"mag\": 9729}" && R linear
scene minnear "{$UV, \"mag\": null, \"min\": 9986}" && R minnear
# KHR_mesh_quantization: positions as unsigned shorts (moved by the node), normals as
# normalized bytes, texture coordinates as signed shorts, which hold the float scene's
# values exactly: the same image to the bit.
scene float_q "{$WIDE, \"wrap\": [33648, 10497]}" && R float_q
scene quant "{$WIDE, \"wrap\": [33648, 10497], \"quant\": true}" && R quant
# Normals: a byte's step is 1/127, so each component is off by at most 0.5/127 = 0.0039
# before renormalisation, which changes the direction by at most about 2 x 0.0039.
NRM='"normal": [0.6, 0.0, 0.8]'
scene nfloat "{$UV, $NRM}" && R nfloat normal 16x16
scene nquant "{$UV, $NRM, \"quant\": true}" && R nquant normal 16x16
scene undeclared "{$UV, \"quant\": true, \"declare_quant\": false}" && R undeclared albedo 8x8
run_queue

check_queued "texCoord 2: renders" 0 uv1none
check "texCoord 2 is dropped with a warning" grep -q "uses TEXCOORD_2, only TEXCOORD_0 and TEXCOORD_1" "$tmp/last"
check_queued "LINEAR: renders" 0 linear
check "LINEAR: bilinear between texel centres" python3 -c "
import math, subprocess, sys
lin = lambda c: (((c/255) + 0.055) / 1.055) ** 2.4
bad = 0
row = [float(v) for v in subprocess.check_output([sys.argv[1], 'at', sys.argv[2], 'R'] +
                                                 [str(c) for x in range(6, 42) for c in (x, 30)]).split()]
for x in range(6, 42):
    p = (x + 0.5) / 12 - 0.5; i = math.floor(p); f = p - i
    want = (1 - f) * lin(40 + 60 * i) + f * lin(40 + 60 * (i + 1))
    got = row[x - 6]
    if abs(got - want) > 1e-3 * want + 1e-4: bad += 1; print(x, got, want)
sys.exit(1 if bad else 0)" "$TESTTOOL" "$tmp/linear.exr"
check_queued "no magFilter: renders" 0 minnear
check "no magFilter: minFilter NEAREST_MIPMAP_LINEAR samples nearest" \
    python3 "$tmp/probe.py" "$tmp/minnear.exr" "{$UV}" "$TESTTOOL" $N
check_queued "float mesh renders" 0 float_q
check_queued "quantized mesh renders" 0 quant
check "quantized mesh: the float original's image exactly" "$G" diff "$tmp/float_q.exr" "$tmp/quant.exr" --max-error 0
check_queued "float normals render" 0 nfloat
check_queued "quantized normals render" 0 nquant
check "quantized normals within their step" "$G" diff "$tmp/nfloat.exr" "$tmp/nquant.exr" --max-error 0.008
check_queued "quantized attributes without KHR_mesh_quantization" 1 undeclared
check "error names the file and the extension" grep -q "undeclared.gltf: .*not allowed for attribute .*needs KHR_mesh_quantization" "$tmp/last"
check "no output after the error" test ! -e "$tmp/undeclared.exr"
finish
