#!/usr/bin/env bash
# primitives.sh: glTF primitive modes. Points and lines (modes 0-3) are skipped with one
# warning each naming the primitive and its mode; triangles, strips and fans are drawn
# (MeshPrimitiveModes: seven meshes of one primitive each over the same hexagon: 6 + 4 + 6
# triangles). A file refused for a required extension prints the refusal only. --strict
# makes the skipping an error.
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
# --strict (render, compare, info, batch): a warning about the file is an error, exit 1, and
# nothing is written: no report, no image. A triangle beside a POINTS primitive.
python3 - "$tmp/points.gltf" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf()
tri = g.primitive([0, 0, 0, 1, 0, 0, 0, 1, 0])
g.scene([g.node(mesh=g.mesh(tri, dict(tri, mode=0)))])
g.write(sys.argv[1])
PY
P=$tmp/points.gltf
check "without --strict: info reports it" sh -c '"$0" info "$1" >/dev/null 2>"$2"' "$G" "$P" "$tmp/plain.err"
check "... with a warning" grep -qF "gonio: warning: $P: mesh 0 primitive 1: mode POINTS" "$tmp/plain.err"
"$G" info --strict "$P" >"$tmp/strict.out" 2>"$tmp/strict.err"
check "info --strict: exit 1" test $? = 1
check "... no report" test ! -s "$tmp/strict.out"
check "... the warning said as an error" grep -qF "gonio: error: $P: mesh 0 primitive 1: mode POINTS" "$tmp/strict.err"
check "... and why it is one" grep -qF "$P: 1 warning, which --strict makes errors: nothing written" "$tmp/strict.err"
check_fails "render --strict: exit 1" 1 "$G" render --strict "$P" -o "$tmp/strict.png" --size 8x8 --spp 1
check "... no image" test ! -e "$tmp/strict.png"
check_fails "compare --strict: exit 1" 1 "$G" compare --strict "$P" -o "$tmp/cmp" --size 8x8 --spp 1
check "... no image" test -z "$(ls -A "$tmp/cmp" 2>/dev/null)"
check_fails "render: an option it ignores is a warning too" 1 "$G" render --strict scenes/cornell.gltf -o "$tmp/c.exr" --size 8x8 --exposure 1
check "... said as an error" grep -qF "gonio: error: --exposure applies to the PNG only" "$tmp/last"
printf '%s\n' "info --strict $P" "info $P" >"$tmp/lines"
check_fails "batch: a --strict line fails" 1 "$G" batch "$tmp/lines"
check "... and the next line's warning is a warning again" grep -qF "gonio: warning: $P" "$tmp/last"
printf '%s\n' "info $P" "info scenes/cornell.gltf" >"$tmp/lines"
check_fails "batch --strict: every line as with --strict" 1 "$G" batch --strict "$tmp/lines"
check "... the line with a warning failed, the clean one did not" grep -qF "batch: $tmp/lines:1 gave exit status 1" "$tmp/last"
check "... (one failure)" test "$(grep -c 'gave exit status' "$tmp/last")" = 1
check "--strict is in --help" sh -c '"$0" render --help | grep -q -- --strict && "$0" info --help | grep -q -- --strict && "$0" batch --help | grep -q -- --strict && "$0" compare --help | grep -q -- --strict' "$G"

# a refusal: the error, nothing else
python3 -c 'import sys, gltf_fixture as gf; g = gf.Gltf(); g.require("EXT_gonio_unknown"); g.write(sys.argv[1])' "$tmp/refused.gltf"
check_fails "a file requiring an unsupported extension is refused" 1 "$G" info "$tmp/refused.gltf"
[ "$(wc -l <"$tmp/last")" = 1 ] && grep -q "requires unsupported extension EXT_gonio_unknown" "$tmp/last" && pass ||
    fail "the refusal is not the only message: $(cat "$tmp/last")"
finish
