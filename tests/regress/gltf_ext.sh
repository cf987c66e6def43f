#!/usr/bin/env bash
# gltf_ext.sh: compressed meshes, material variants and the extension rules.
# Draco and meshopt: gonio's Cornell box and teapot encoded by the libraries' own encoders
# (testtool compress: Draco without quantization, meshopt's lossless codecs) must render bit
# for bit like the originals; corrupt compressed bytes are an error (exit 1) naming the file
# and the primitive or buffer view, with no output. Variants: --variant NAME must render like
# the same scene with that variant's materials written in, and unknown names fail.
# Extensions: an unknown required one is an error naming it, unknown used ones warn once each.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
T=$TESTTOOL
command -v python3 >/dev/null || skip_all "python3 is needed to edit the test scenes"
R="--spp 4 --size 96x72 --quiet"

# the scenes (gonio's own Cornell box, shared with untrusted.sh: lib.sh, fixture)
declare -A src
src[cornell]=$(fixture cornell.gltf "$G" scene cornell -o {}) && src[teapot]=$tmp/teapot.gltf &&
    "$G" teapot --level 4 -o "${src[teapot]}" || { fail "scenes"; finish; exit; }
# Q ID SCENE ARGS...: queues a render (lib.sh: queue); the script's renders run in one batch,
# after the compressed and edited scenes are written, then the checks read each one's status,
# output ($tmp/last) and image.
Q() { local id=$1 f=$2; shift 2; queue "$id" render "$f" -o "$tmp/$id.exr" $R "$@"; }
for s in cornell teapot; do
    for k in draco meshopt; do
        check "$s: $k encode" "$T" compress $k "${src[$s]}" "$tmp/$s-$k.gltf"
        check "$s: $k file uses the extension" grep -q "$([ $k = draco ] && echo KHR_draco_mesh_compression || echo EXT_meshopt_compression)" "$tmp/$s-$k.gltf"
    done
done

# Corrupt compressed bytes: every 7th byte of the last buffer (the compressed one) flipped.
for k in draco meshopt; do
    python3 - "$tmp/cornell-$k.gltf" "$tmp/bad-$k.gltf" <<'PY'
import base64, sys
import gltf_fixture as gf
g = gf.Gltf.load(sys.argv[1])
b = g.doc["buffers"][-1]
raw = bytearray(base64.b64decode(b["uri"].split(",")[1]))
for i in range(0, len(raw), 7):
    raw[i] ^= 0x5A
b["uri"] = gf.data_uri(bytes(raw))
g.write(sys.argv[2])
PY
done

# Stale bounds: the Draco and meshopt teapots with every float accessor's min/max shrunk to
# half (as a file whose bounds were kept from before its encoding has them) warn once,
# naming them as stale, not once an accessor; the plain teapot so edited warns of its data.
python3 - "$tmp/teapot-draco.gltf" "$tmp/stale-draco.gltf" "${src[teapot]}" "$tmp/stale-plain.gltf" \
    "$tmp/teapot-meshopt.gltf" "$tmp/stale-meshopt.gltf" <<'PY'
import sys
import gltf_fixture as gf
for src, out in ((sys.argv[1], sys.argv[2]), (sys.argv[3], sys.argv[4]), (sys.argv[5], sys.argv[6])):
    g = gf.Gltf.load(src)
    for a in g.doc["accessors"]:
        if a.get("componentType") == gf.FLOAT and "max" in a:
            a["min"], a["max"] = [0.5 * v for v in a["min"]], [0.5 * v for v in a["max"]]
    g.write(out)
PY
for k in draco meshopt; do
    check "stale bounds of $k-decoded data: the file loads" sh -c '"$0" info "$1" 2>"$2" >/dev/null' "$G" "$tmp/stale-$k.gltf" "$tmp/stale.err"
    check "... with one line saying they are stale" test "$(grep -c 'decoded from compressed data (the first: accessor [0-9]*) lie outside the min/max the file declares for them: its bounds are stale' "$tmp/stale.err")" = 1
    check "... and no other warning" test "$(grep -c warning "$tmp/stale.err")" = 1
done
check "the same bounds of plain data: the file loads" sh -c '"$0" info "$1" 2>"$2" >/dev/null' "$G" "$tmp/stale-plain.gltf" "$tmp/stale.err"
check "... warning of the accessor's element outside them" grep -q "lies outside its declared min/max" "$tmp/stale.err"

# Variants: "green_left" maps the red wall (mesh 3) to the green material (2).
python3 - "${src[cornell]}" "$tmp/variants.gltf" "$tmp/green.gltf" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf.load(sys.argv[1])
g.variants("as_is", "green_left")
p = g.doc["meshes"][3]["primitives"][0]
assert p["material"] == 1
g.extend(p, "KHR_materials_variants", mappings=[{"material": 2, "variants": [1]}, {"material": 1, "variants": [0]}])
g.write(sys.argv[2])
del p["extensions"]
p["material"] = 2
g.write(sys.argv[3])
PY

# ---- the renders, queued ------------------------------------------------------------------
for s in cornell teapot; do
    Q $s "${src[$s]}"
    for k in draco meshopt; do Q $s-$k "$tmp/$s-$k.gltf"; done
done
for k in draco meshopt; do Q bad-$k "$tmp/bad-$k.gltf"; done
Q v-default "$tmp/variants.gltf"
Q v-green "$tmp/variants.gltf" --variant green_left
Q green "$tmp/green.gltf"
Q v-x "$tmp/variants.gltf" --variant nosuch
run_queue

for s in cornell teapot; do
    check_queued "$s: render" 0 $s
    for k in draco meshopt; do
        check_queued "$s: $k render" 0 $s-$k
        check "$s: $k decodes to the same image" "$T" same "$tmp/$s.exr" "$tmp/$s-$k.exr"
    done
done

for k in draco meshopt; do
    check_queued "$k: corrupt data is an error" 1 bad-$k
    what=$([ $k = draco ] && echo "primitives\[0\].extensions.KHR_draco_mesh_compression: Draco cannot decode" ||
        echo "(EXT_meshopt_compression): meshoptimizer cannot decode")
    check "$k: the error names the file and the part" grep -q "bad-$k.gltf: .*$what" "$tmp/last"
    check "$k: no output" test ! -e "$tmp/bad-$k.exr"
done

check "variants: info lists them" sh -c "'$G' info '$tmp/variants.gltf' | grep -q 'variant 1 .*\"green_left\"'"
check_queued "variants: default render" 0 v-default
check "variants: default is the file's own materials" "$T" same "$tmp/cornell.exr" "$tmp/v-default.exr"
check_queued "variants: --variant green_left" 0 v-green
check_queued "variants: reference" 0 green
check "variants: green_left has its material" "$T" same "$tmp/green.exr" "$tmp/v-green.exr"
check_fails "variants: green_left differs from the default" 1 "$T" same "$tmp/cornell.exr" "$tmp/v-green.exr"
check_queued "variants: unknown name" 1 v-x
check "variants: the error lists the variants" grep -q "no material variant 'nosuch' (variants: 'as_is', 'green_left')" "$tmp/last"

# Extension rules.
sed 's/"asset": {/"extensionsRequired": ["EXT_nosuch_a"],\n  "asset": {/' "${src[cornell]}" >"$tmp/req.gltf"
check_fails "required unknown extension" 1 "$G" info "$tmp/req.gltf"
check "the error names it" grep -q "req.gltf: requires unsupported extension EXT_nosuch_a" "$tmp/last"
sed 's/"extensionsUsed": \[/"extensionsUsed": ["EXT_nosuch_b","EXT_nosuch_c","EXT_nosuch_b",/' "${src[cornell]}" >"$tmp/used.gltf"
check_fails "used unknown extensions only warn" 0 "$G" info "$tmp/used.gltf"
for e in EXT_nosuch_b EXT_nosuch_c; do
    check "one warning for $e" test "$(grep -c "warning: .*used.gltf: uses unsupported extension $e" "$tmp/last")" = 1
done
finish
