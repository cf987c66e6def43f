#!/usr/bin/env bash
# primitives.sh: glTF primitive modes. Points and lines (modes 0-3) are skipped with one
# warning each naming the primitive and its mode; triangles, strips and fans are drawn
# (MeshPrimitiveModes: seven meshes of one primitive each over the same hexagon: 6 + 4 + 6
# triangles). A file refused for a required extension prints the refusal only.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
A=${GONIO_ASSETS:-}
f=$A/gltf/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf
if [ -n "$A" ] && [ -f "$f" ]; then
    check "MeshPrimitiveModes renders" "$G" render "$f" --size 32x32 --spp 1 --quiet -o "$tmp/modes.exr"
    "$G" info "$f" >"$tmp/info" 2>"$tmp/warn" || fail "gonio info MeshPrimitiveModes"
    [ "$(grep -c warning "$tmp/warn")" = 4 ] && pass || fail "not one warning per skipped primitive: $(cat "$tmp/warn")"
    for m in "0 'mesh with POINTS' primitive 0: mode POINTS" "1 'mesh with LINES' primitive 0: mode LINES" \
        "2 'mesh with LINE_LOOP' primitive 0: mode LINE_LOOP" "3 'mesh with LINE_STRIP' primitive 0: mode LINE_STRIP"; do
        grep -q "mesh $m is not supported (skipped)" "$tmp/warn" && pass || fail "no warning naming mesh $m"
    done
    grep -q "^triangles *16$" "$tmp/info" && pass || fail "triangles, strips and fans: $(grep triangles "$tmp/info")"
else
    echo "  (MeshPrimitiveModes skipped: no test assets)"
fi
# a refusal: the error, nothing else
python3 -c 'import sys, gltf_fixture as gf; g = gf.Gltf(); g.require("KHR_xmp_json_ld"); g.write(sys.argv[1])' "$tmp/refused.gltf"
check_fails "a file requiring an unsupported extension is refused" 1 "$G" info "$tmp/refused.gltf"
[ "$(wc -l <"$tmp/last")" = 1 ] && grep -q "requires unsupported extension KHR_xmp_json_ld" "$tmp/last" && pass ||
    fail "the refusal is not the only message: $(cat "$tmp/last")"
finish
