#!/usr/bin/env bash
# specgloss.sh: KHR_materials_pbrSpecularGlossiness rendered against materials written by
# hand in the metallic-roughness model, from the extension's definition of its inputs
# (c_diff = diffuse (1 - max(specular)), F0 = specular, alpha = (1 - glossiness)^2) and the
# conversion KHR_materials_specular gives for it (specularColorFactor = specular at
# KHR_materials_ior 0, metallic 0, roughness = 1 - glossiness): a quad with factors only must
# render as its hand-converted twin; a quad whose specularGlossinessTexture is white and
# opaque on its left half and black and clear (glossiness 0) on its right must render, half by
# half, as two untextured twins. Then the Khronos sample SpecGlossVsMetalRough (a bottle in
# each model, made to look alike) seen straight on from afar: its halves' mean luminances
# agree; `gonio info` names the extension as supported. Dyadic factors keep both paths exact.
# KHR_materials_specular and _ior beside it are ignored with a warning each (they do not
# combine with it).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
A=${GONIO_ASSETS:-}
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
W=16 H=8

# gen.py OUT.gltf MATERIAL-JSON EXTENSIONS-JSON: the quad view (gltf_fixture), the 2x1 texture
# (left texel 255 in every channel, right 0) as texture 0, NEAREST filtering.
cat >"$tmp/gen.py" <<'PY'
import json, sys
import gltf_fixture as gf
out, material, exts = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3])
g = gf.Gltf()
g.use(*exts)
g.texture(g.image(gf.png(2, 1, bytes([255] * 4 + [0] * 4))), g.sampler(gf.NEAREST, gf.NEAREST))
g.quad_view(g.quad(g.material(material)))
g.write(out)
PY

# mr DIFFUSE(3) SPECULAR(3) GLOSSINESS: the metallic-roughness twin of a spec-gloss material,
# converted here from the extension's formulas
mr() {
    python3 -c '
import json, sys
d, s, g = json.loads(sys.argv[1]), json.loads(sys.argv[2]), float(sys.argv[3])
k = 1 - max(s)
print(json.dumps({"pbrMetallicRoughness": {"baseColorFactor": [c * k for c in d] + [1], "metallicFactor": 0,
                                           "roughnessFactor": 1 - g},
                  "extensions": {"KHR_materials_specular": {"specularColorFactor": s},
                                 "KHR_materials_ior": {"ior": 0}}}))' "$@"
}
MR_EXT='["KHR_materials_specular","KHR_materials_ior"]' SG_EXT='["KHR_materials_pbrSpecularGlossiness"]'
D='[0.75, 0.5, 0.25]' S='[0.5, 0.25, 0.125]'
gen() { python3 "$tmp/gen.py" "$tmp/$1.gltf" "$2" "$3" || fail "$1: scene"; }
gen sg-factors '{"extensions": {"KHR_materials_pbrSpecularGlossiness": {"diffuseFactor": [0.75, 0.5, 0.25, 1],
    "specularFactor": '"$S"', "glossinessFactor": 0.75}}}' "$SG_EXT"
gen mr-factors "$(mr "$D" "$S" 0.75)" "$MR_EXT"
gen sg-tex '{"extensions": {"KHR_materials_pbrSpecularGlossiness": {"diffuseFactor": [0.75, 0.5, 0.25, 1],
    "specularFactor": '"$S"', "glossinessFactor": 0.75, "specularGlossinessTexture": {"index": 0}}}}' "$SG_EXT"
gen mr-white "$(mr "$D" "$S" 0.75)" "$MR_EXT"  # the left texel: specular x 1, glossiness x 1
gen mr-black "$(mr "$D" '[0, 0, 0]' 0)" "$MR_EXT" # the right one: specular x 0, glossiness x 0

# the PBR extensions of metallic-roughness beside it: ignored, saying so (checked below)
gen sg-mixed '{"extensions": {"KHR_materials_pbrSpecularGlossiness": {"diffuseFactor": [0.75, 0.5, 0.25, 1],
    "specularFactor": '"$S"', "glossinessFactor": 0.75}, "KHR_materials_specular": {"specularFactor": 0.5},
    "KHR_materials_ior": {"ior": 2}}}' '["KHR_materials_pbrSpecularGlossiness","KHR_materials_specular","KHR_materials_ior"]'
# a bad value (checked below)
gen bad '{"extensions": {"KHR_materials_pbrSpecularGlossiness": {"specularFactor": [0.5, "x", 0.5]}}}' "$SG_EXT"
f=$A/gltf/SpecGlossVsMetalRough/glTF/SpecGlossVsMetalRough.gltf
assets=0
[ -n "$A" ] && [ -f "$f" ] && assets=1

# ---- the renders, queued (lib.sh: queue), run in one batch --------------------------------
for s in sg-factors mr-factors sg-tex mr-white mr-black sg-mixed; do
    queue $s render "$tmp/$s.gltf" --spp 4 --size ${W}x$H --env 1 --compression none --quiet -o "$tmp/$s.exr"
done
queue bad render "$tmp/bad.gltf" --spp 1 --size 8x8 -o "$tmp/bad.exr"
# From 5 m away with a 3.665 degree view the image is 0.32 m wide: the bottles (at x = -0.08
# and +0.08, the same turn) fill a half each, nearly as a translated copy.
[ $assets = 1 ] && queue sgmr render "$f" --size 64x64 --spp 16 --look-at 0,0.03,5,0,0.03,0 \
    --fov 3.665 --compression none --quiet -o "$tmp/sgmr.exr"
run_queue

for s in sg-factors mr-factors sg-tex mr-white mr-black; do
    check_queued "$s renders" 0 $s
done

T=$(dirname "$0")/../tool
check "factors: the spec-gloss quad renders as its metallic-roughness twin" \
    same_halves "$tmp/sg-factors.exr" "$tmp/mr-factors.exr" "$tmp/mr-factors.exr" $W
check "specularGlossinessTexture: RGB scales the specular colour, A the glossiness, texel by texel" \
    same_halves "$tmp/sg-tex.exr" "$tmp/mr-white.exr" "$tmp/mr-black.exr" $W

check_queued "spec-gloss beside KHR_materials_specular and _ior renders" 0 sg-mixed
for x in specular ior; do
    check "... warning that KHR_materials_$x does not combine with it" \
        grep -qF "material 0: KHR_materials_$x does not combine with KHR_materials_pbrSpecularGlossiness (ignored)" "$tmp/last"
done
check "... and renders as the spec-gloss material alone" "$TESTTOOL" same "$tmp/sg-factors.exr" "$tmp/sg-mixed.exr"

# a bad value: an error naming the JSON path, exit 1
check_queued "a specularFactor of the wrong type is refused" 1 bad
check "... naming its JSON path" grep -q "materials\[0\].extensions.KHR_materials_pbrSpecularGlossiness.specularFactor" "$tmp/last"

[ $assets = 1 ] || {
    echo "  (SpecGlossVsMetalRough skipped: no test assets)"
    finish
    exit
}
check "gonio info lists the extension as supported" sh -c "'$G' info '$f' | grep -q 'KHR_materials_pbrSpecularGlossiness (required): supported'"
check_queued "SpecGlossVsMetalRough renders straight on" 0 sgmr
cat >"$tmp/means.py" <<'PY'
import sys
sys.path.insert(0, sys.argv[2])
import exrtool
_, ch = exrtool.read(sys.argv[1])
R, G, B = (ch[c][1] for c in "RGB")
w = int(sys.argv[3]); h = len(R) // w
lum = [0.2126 * R[i] + 0.7152 * G[i] + 0.0722 * B[i] for i in range(len(R))]
half = lambda x0: sum(lum[y * w + x] for y in range(h) for x in range(x0, x0 + w // 2)) / (h * w // 2)
l, r = half(0), half(w // 2)
print("mean luminance: metal-rough half %.4f, spec-gloss half %.4f" % (l, r))
sys.exit(0 if abs(l - r) <= 0.03 * l else 1)
PY
check "SpecGlossVsMetalRough: the halves' mean luminances agree within 3%" python3 "$tmp/means.py" "$tmp/sgmr.exr" "$T" 64
finish
