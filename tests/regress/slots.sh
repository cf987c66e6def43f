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

# gen.py OUT.gltf EXT FACTOR-KEY FACTOR-JSON TEXTURE-KEY|-: the quad view (gltf_fixture), its
# material's base a grey dielectric, with EXT's FACTOR and (unless -) its texture
# TEXTURE-KEY: a 2x1 image, left texel all 0, right all 255, NEAREST filtering.
cat >"$tmp/gen.py" <<'PY'
import json, sys
import gltf_fixture as gf
out, ext, key, value, tex = sys.argv[1], sys.argv[2], sys.argv[3], json.loads(sys.argv[4]), sys.argv[5]
g = gf.Gltf()
g.texture(g.image(gf.png(2, 1, bytes([0] * 4 + [255] * 4))), g.sampler(gf.NEAREST, gf.NEAREST))
m = {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 0.4}}
block = g.extend(m, ext, {key: value})
if tex != "-":
    block[tex] = {"index": 0}
g.quad_view(g.quad(g.material(m)))
g.write(out)
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
    check "$1: $6 scales $3 texel by texel" same_halves "$tmp/$1-tex.exr" "$tmp/$1-zero.exr" "$tmp/$1-one.exr" $W
}
slot specular KHR_materials_specular specularFactor 1 0 specularTexture
slot specular-color KHR_materials_specular specularColorFactor "[1, 1, 1]" "[0, 0, 0]" specularColorTexture
slot transmission KHR_materials_transmission transmissionFactor 1 0 transmissionTexture
run_queue
finish
