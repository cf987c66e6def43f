#!/usr/bin/env bash
# render.sh: whole-program checks of `gonio render`, `info` and `devices`: images against
# analytic references computed independently (tests/tool/testtool.c), determinism, output
# files and headers, and the handling of bad flags and bad files.
. "$(dirname "$0")/../lib.sh"
G=$GONIO

# ---- analytic references: depth and normals of a tilted plane and of a sphere seen from
# inside (no silhouettes, so every pixel has an exact answer) -----------------------------
for s in plane inside-sphere; do
    check "testtool scene $s" "$TESTTOOL" scene $s "$tmp/$s.gltf"
    for aov in depth normal; do
        check "testtool ref $s $aov" "$TESTTOOL" ref $s $aov 96 96 "$tmp/$s-$aov-ref.exr"
        queue "$s-$aov" render "$tmp/$s.gltf" -o "$tmp/$s-$aov.exr" --mode $aov --spp 1 --size 96x96 --camera 0 --quiet
    done
done
run_queue # (the renders of a block in one batch: lib.sh, queue)
for s in plane inside-sphere; do for aov in depth normal; do check_queued "render $s $aov" 0 "$s-$aov"; done; done
# The plane is exact up to float rounding: 1e-4 is far below one pixel's depth step.
check "plane depth matches the analytic depth" "$G" diff "$tmp/plane-depth.exr" \
    "$tmp/plane-depth-ref.exr" --max-error 1e-4 --quiet
check "plane normal matches the analytic normal" "$G" diff "$tmp/plane-normal.exr" \
    "$tmp/plane-normal-ref.exr" --max-error 1e-5 --quiet
# The sphere is a 512x256 tessellation: radial error <= 1 - cos(pi/256) = 7.5e-5, so depth
# within 2e-4 and interpolated normals within 2e-3 of the analytic ones.
check "sphere depth matches the analytic depth" "$G" diff "$tmp/inside-sphere-depth.exr" \
    "$tmp/inside-sphere-depth-ref.exr" --max-error 2e-4 --quiet
check "sphere normals match the analytic normals" "$G" diff "$tmp/inside-sphere-normal.exr" \
    "$tmp/inside-sphere-normal-ref.exr" --max-error 2e-3 --max-rmse 5e-4 --quiet
# ...and the comparisons can fail: a reference whose rays are off by a quarter pixel does not pass.
check "testtool ref shifted" "$TESTTOOL" ref plane depth 96 96 "$tmp/plane-shifted.exr" 0.25
check_fails "a quarter-pixel shift fails the plane depth comparison" 1 "$G" diff \
    "$tmp/plane-depth.exr" "$tmp/plane-shifted.exr" --max-error 1e-4 --quiet
check "testtool ref shifted sphere" "$TESTTOOL" ref inside-sphere normal 96 96 "$tmp/sphere-shifted.exr" 0.25
check_fails "a quarter-pixel shift fails the sphere normal comparison" 1 "$G" diff \
    "$tmp/inside-sphere-normal.exr" "$tmp/sphere-shifted.exr" --max-error 2e-3 --max-rmse 5e-4 --quiet

# ---- the default scene, outputs and headers --------------------------------------------
C=scenes/cornell.gltf
check "render the Cornell box (phong) with AOVs" "$G" render $C -o "$tmp/c.exr" --png "$tmp/c.png" \
    --spp 4 --size 64x64 --aov normal,albedo,depth --seed 7 --quiet
check "EXR written" test -s "$tmp/c.exr"
check "PNG written" test -s "$tmp/c.png"
exrheader "$tmp/c.exr" >"$tmp/hdr.txt" 2>&1
for want in 'gonio:spp' 'gonio:seed' 'gonio:mode' 'gonio:seconds' 'gonio:command' \
    'normal.X,' 'albedo.R,' 'depth.Z,' ' R, 32-bit floating' ' A, 32-bit floating'; do
    check "EXR header has $want" grep -qF -- "$want" "$tmp/hdr.txt"
done
check "spp recorded" grep -q 'gonio:spp (type int): 4' "$tmp/hdr.txt"

# ---- the output's format is the one its name says ----------------------------------------
magic() { head -c 4 "$1" | od -An -tx1 | tr -d ' \n'; } # first 4 bytes, hex
is_exr() { [ "$(magic "$1")" = 762f3101 ]; }
is_png() { [ "$(magic "$1")" = 89504e47 ]; }
# (this block's and the next two's renders in one batch)
queue o render $C -o "$tmp/o.png" --spp 1 --size 16x16 --quiet
queue O render $C -o "$tmp/o.EXR" --spp 1 --size 16x16 --quiet
queue o2 render $C --png "$tmp/o2.png" --spp 1 --size 16x16 --quiet
queue ball-png brdf lambert --sphere -o "$tmp/ball.png" --size 16x16 --spp 2
queue ball-exr brdf lambert --sphere -o "$tmp/ball.exr" --size 16x16 --spp 2
le32() { od -An -tu4 -j "$2" -N4 "$1" | tr -d ' '; }
for sc in teapot cornell; do
    check "scene $sc -o x.glb" "$G" scene $sc -o "$tmp/$sc.glb"
    check "scene $sc -o x.gltf" "$G" scene $sc -o "$tmp/$sc.gltf"
    queue "$sc-glb" render "$tmp/$sc.glb" -o "$tmp/$sc-glb.exr" --mode phong --spp 2 --size 32x32 --quiet
    queue "$sc-gltf" render "$tmp/$sc.gltf" -o "$tmp/$sc-gltf.exr" --mode phong --spp 2 --size 32x32 --quiet
done
aov_sets=()
for set in normal albedo depth variance depth,normal albedo,variance normal,albedo,depth,variance; do
    if [ "${set#*,}" != "$set" ] && [ "$set" != normal,albedo,depth,variance ]; then in_tier slow || continue; else in_tier fast || continue; fi
    aov_sets+=("$set")
    queue "aov-$set" render $C -o "$tmp/aov-$set.exr" --mode phong --spp 2 --size 16x16 --aov $set --quiet
done
run_queue
check_queued "render -o x.png" 0 o
check "render -o x.png writes a PNG" is_png "$tmp/o.png"
check "render -o x.exr writes an EXR" is_exr "$tmp/c.exr"
check "render --png writes a PNG" is_png "$tmp/c.png"
check_queued "render -o X.EXR" 0 O
check "render -o X.EXR writes an EXR" is_exr "$tmp/o.EXR"
check_queued "render --png alone" 0 o2
check "render -o x.png is the --png PNG" cmp "$tmp/o.png" "$tmp/o2.png"
for bad in "-o $tmp/bad.jpg" "-o $tmp/bad" "--png $tmp/bad.exr" "-o $tmp/bad.exr --png $tmp/bad.tif"; do
    check_fails "render $bad: a usage error" 2 "$G" render $C $bad --spp 1 --size 16x16 --quiet
done
check "no output for a bad name" sh -c "! ls '$tmp' | grep -q '^bad'"
check_fails "--half without an EXR output" 2 "$G" render $C --png "$tmp/bad.png" --half --quiet
check_fails "an unknown --compression" 2 "$G" render $C -o "$tmp/bad.exr" --compression dwaa --quiet
check_fails "brdf: the lobe plot is no EXR" 2 "$G" brdf lambert -o "$tmp/bad.exr"
check_fails "brdf --sphere -o x.jpg" 2 "$G" brdf lambert --sphere -o "$tmp/bad.jpg"
check_queued "brdf --sphere -o x.png" 0 ball-png
check "brdf --sphere -o x.png writes a PNG" is_png "$tmp/ball.png"
check_queued "brdf --sphere -o x.exr" 0 ball-exr
check "brdf --sphere -o x.exr writes an EXR" is_exr "$tmp/ball.exr"
check "brdf lobe -o x.png" "$G" brdf lambert -o "$tmp/lobe.png"
check "brdf lobe writes a PNG" is_png "$tmp/lobe.png"
check_fails "teapot -o x.obj" 2 "$G" teapot -o "$tmp/bad.obj"
# The teapot is an open mesh (the spout and the lid's gap show its inside): double-sided.
check "teapot --level 2 -o x.gltf" "$G" teapot --level 2 -o "$tmp/teapot-2.gltf"
for f in "$tmp/teapot.gltf" "$tmp/teapot-2.gltf"; do
    check "$(basename "$f"): its material is double-sided" python3 -c \
        'import json, sys; assert json.load(open(sys.argv[1]))["materials"][0]["doubleSided"] is True' "$f"
done
# .glb is binary glTF (magic, version 2, total length = file size) that info and render read,
# and the same scene as the .gltf: identical pixels and the same gonio:scene hash.
# (the files are written and rendered above, in the batch)
for sc in teapot cornell; do
    check "$sc.glb: GLB magic" test "$(magic "$tmp/$sc.glb")" = 676c5446
    check "$sc.glb: version 2 and its length" test "$(le32 "$tmp/$sc.glb" 4) $(le32 "$tmp/$sc.glb" 8)" = "2 $(stat -c %s "$tmp/$sc.glb")"
    check "$sc.gltf is JSON" grep -q '"asset"' "$tmp/$sc.gltf"
    check "info reads $sc.glb" "$G" info "$tmp/$sc.glb"
    check_queued "render $sc.glb" 0 "$sc-glb"
    check_queued "render $sc.gltf" 0 "$sc-gltf"
    check "$sc: .glb and .gltf render the same pixels" "$G" diff "$tmp/$sc-glb.exr" "$tmp/$sc-gltf.exr" --max-error 0 --quiet
    check "$sc: .glb and .gltf are the same gonio:scene" test \
        "$(exrheader "$tmp/$sc-glb.exr" | grep 'gonio:scene ')" = "$(exrheader "$tmp/$sc-gltf.exr" | grep 'gonio:scene ')"
done

# ---- --aov writes exactly the AOVs listed ------------------------------------------------
channels() { exrheader "$1" | sed -n 's/^    \([^,]*\), .*/\1/p' | sort | tr '\n' ' '; }
# (the fast tier: every AOV alone and all together; the slow tier: the pairs)
for set in "${aov_sets[@]}"; do
    check_queued "--aov $set" 0 "aov-$set"
    want="A B G R"
    case ,$set, in *,albedo,*) want="$want albedo.B albedo.G albedo.R" ;; esac
    case ,$set, in *,depth,*) want="$want depth.Z" ;; esac
    case ,$set, in *,normal,*) want="$want normal.X normal.Y normal.Z" ;; esac
    case ,$set, in *,variance,*) want="$want variance.B variance.G variance.R" ;; esac
    want=$(echo $want | tr ' ' '\n' | sort | tr '\n' ' ')
    check "--aov $set: channels $want" test "$(channels "$tmp/aov-$set.exr")" = "$want"
done
check_fails "--aov bogus" 2 "$G" render $C -o "$tmp/bad.exr" --aov normal,bogus --quiet
# (this block's renders first, in one batch)
queue plane-aov render "$tmp/plane.gltf" -o "$tmp/plane-aov.exr" --mode albedo --aov depth --spp 1 --size 96x96 --camera 0 --quiet
queue dm render $C -o "$tmp/dm.exr" --mode depth --spp 1 --size 32x32 --quiet
queue da render $C -o "$tmp/da.exr" --mode albedo --aov depth --spp 1 --size 32x32 --quiet
for comp in none rle zips zip piz pxr24 b44 b44a; do
    case $comp in none | zip | piz | b44) in_tier fast || [ $comp = zip ] || continue ;; *) in_tier slow || continue ;; esac
    queue "z-$comp" render $C -o "$tmp/z-$comp.exr" --mode albedo --spp 1 --size 32x32 --compression $comp --quiet
done
queue h render $C -o "$tmp/h.exr" --mode albedo --spp 1 --size 32x32 --half --aov depth --quiet
queue pd render "$tmp/plane.gltf" --png "$tmp/pd.png" --mode depth --spp 1 --size 96x96 --camera 0 --quiet
queue pn render "$tmp/plane.gltf" --png "$tmp/pn.png" --mode normal --spp 1 --size 96x96 --camera 0 --quiet
queue cn render $C -o "$tmp/cn.png" --mode normal --spp 1 --size 64x64 --quiet
queue cc render $C -o "$tmp/cc.png" --mode cost --spp 1 --size 64x64 --quiet
for m in normal albedo depth cost phong; do
    queue "m-$m" render $C -o "$tmp/m-$m.exr" --mode $m --spp 2 --size 32x32 --quiet
done
queue c2 render $C -o "$tmp/c2.exr" --spp 4 --size 64x64 --aov normal,albedo,depth --seed 7 --quiet
queue c3 render $C -o "$tmp/c3.exr" --spp 4 --size 64x64 --seed 8 --quiet
run_queue
# The depth AOV is the depth mode's image: 0 (not +inf) where nothing is hit, in both.
check_queued "depth AOV of the plane" 0 plane-aov
check "pick the plane's depth.Z" "$TESTTOOL" pick "$tmp/plane-aov.exr" depth.Z "$tmp/plane-aov-z.exr"
check "the depth AOV matches the analytic depth" "$G" diff "$tmp/plane-aov-z.exr" "$tmp/plane-depth-ref.exr" --max-error 1e-4 --quiet
check_queued "cornell depth mode" 0 dm
check_queued "cornell depth AOV" 0 da
check "pick depth.Z" "$TESTTOOL" pick "$tmp/da.exr" depth.Z "$tmp/dz.exr"
check "depth mode = depth AOV, background included" "$G" diff "$tmp/dm.exr" "$tmp/dz.exr" --max-error 0 --quiet
# Pixel (0, 0) of this view is background (coverage 0); the centre is the back wall.
check "(0, 0) is background" test "$("$TESTTOOL" at "$tmp/dm.exr" A 0 0)" = 0
check "background depth is 0 in the depth mode" test "$("$TESTTOOL" at "$tmp/dm.exr" R 0 0)" = 0
check "background depth is 0 in the depth AOV" test "$("$TESTTOOL" at "$tmp/da.exr" depth.Z 0 0)" = 0
check "the back wall has a depth" sh -c "test \"\$('$TESTTOOL' at '$tmp/da.exr' depth.Z 16 16)\" != 0"

# ---- --half and --compression (read back by exrheader and gonio diff) --------------------
# (the fast tier: none, zip, piz and b44; the slow tier the other four, each as before)
for comp in none rle zips zip piz pxr24 b44 b44a; do
    case $comp in none | zip | piz | b44) in_tier fast || [ $comp = zip ] || continue ;; *) in_tier slow || continue ;; esac
    check_queued "--compression $comp" 0 "z-$comp"
    case $comp in rle) says=run-length ;; zips) says="zip, individual" ;; zip) says="zip, multi" ;; *) says="$comp\$" ;; esac
    check "--compression $comp recorded" sh -c "exrheader '$tmp/z-$comp.exr' | grep -q '^compression (type compression): $says'"
done
check "zip is the default" sh -c "exrheader '$tmp/c.exr' | grep -q '^compression (type compression): zip, multi'"
for comp in none rle zips piz; do # lossless: the same floats as zip
    case $comp in none | piz) in_tier fast || continue ;; *) in_tier slow || continue ;; esac
    check "--compression $comp is lossless" "$G" diff "$tmp/z-$comp.exr" "$tmp/z-zip.exr" --max-error 0 --quiet
done
check_queued "--half" 0 h
check "--half: half channels" sh -c "exrheader '$tmp/h.exr' | grep -q 'depth.Z, 16-bit floating-point'"
check "--half: no float channel" sh -c "! exrheader '$tmp/h.exr' | grep -q '32-bit floating'"
# Half keeps 11 significant bits: albedos in [0, 1] within 2^-11.
check "--half: values within half precision" "$G" diff "$tmp/h.exr" "$tmp/z-zip.exr" --max-error 4.9e-4 --quiet
check_fails "--half: but not exactly" 1 "$G" diff "$tmp/h.exr" "$tmp/z-zip.exr" --max-error 0 --quiet

# ---- PNGs of depth, normal and cost are pictures of the data -------------------------------
# The plane fills the view: depth runs from white (nearest) to 20% grey (farthest); normals
# give 0.5 n + 0.5 exactly; the background of the Cornell box's normal PNG is black.
px() { convert "$1" -format "%[fx:int(255*p{$2,$3}.r+0.5)],%[fx:int(255*p{$2,$3}.g+0.5)],%[fx:int(255*p{$2,$3}.b+0.5)]" info:; }
range() { convert "$1" -colorspace gray -format "%[fx:int(255*minima+0.5)] %[fx:int(255*maxima+0.5)]" info:; }
check_queued "plane depth PNG" 0 pd
check "depth PNG spans 51..255 (20% grey to white)" test "$(range "$tmp/pd.png")" = "51 255"
check "depth PNG is the analytic depth, near white" "$TESTTOOL" png depth "$tmp/pd.png" "$tmp/plane-depth-ref.exr"
check_queued "plane normal PNG" 0 pn
check "normal PNG is 0.5 n + 0.5 of the analytic normals" "$TESTTOOL" png normal "$tmp/pn.png" "$tmp/plane-normal-ref.exr"
check_queued "cornell normal PNG" 0 cn
check "normal PNG background is black" test "$(px "$tmp/cn.png" 0 0)" = "0,0,0"
check_queued "cornell cost PNG" 0 cc
check "cost PNG is a heat map: not grey" sh -c "test \"\$(convert '$tmp/cc.png' -colorspace HSL -channel G -separate -format '%[fx:maxima>0.3]' info:)\" = 1"
check "cost PNG reaches the map's top (yellow)" sh -c "convert '$tmp/cc.png' -format '%[fx:maxima.r>0.9]' info: | grep -q 1"
check "no temporary files left" sh -c "! ls -a '$tmp' | grep -q tmp-"
for m in normal albedo depth cost phong; do
    check_queued "mode $m renders" 0 "m-$m"
done
# Same command, same image, bit for bit.
check_queued "render again (in a batch)" 0 c2
check "deterministic: identical pixels" "$G" diff "$tmp/c.exr" "$tmp/c2.exr" --max-error 0 --quiet
check_queued "render with another seed" 0 c3
check_fails "another seed gives other pixels" 1 "$G" diff "$tmp/c.exr" "$tmp/c3.exr" --max-error 0 --quiet
# (the summary lines are checked below, with the last batch's renders)

check "gonio info" sh -c "'$G' info $C >'$tmp/info.txt'"
for f in triangles meshes materials lights 'bvh nodes' 'bvh depth' 'sah cost' 'bvh build'; do
    check "info prints $f" grep -q "$f" "$tmp/info.txt"
done
check "gonio devices lists lavapipe" sh -c "'$G' devices | grep -q llvmpipe"
# Ray queries on lavapipe came with Mesa 24.1 (Debian 12: none in its own 22.3, yes in the
# backports' 25.0): the column says so, and a device without them is told what it lacks.
"$G" devices >"$tmp/devices.txt" 2>&1
mesa=$(sed -n 's/.*llvmpipe Mesa \([0-9]*\)\.\([0-9]*\).*/\1.\2/p' "$tmp/devices.txt" | head -n 1)
check "gonio devices names lavapipe's Mesa version ($mesa)" test -n "$mesa"
if [ -n "$mesa" ] && [ $((${mesa%.*} * 100 + ${mesa#*.})) -ge 2401 ]; then
    check "lavapipe of Mesa $mesa: ray queries yes" grep -Eq '^0 .* cpu .* yes +llvmpipe' "$tmp/devices.txt"
    check_fails "... and no line of what it lacks" 1 grep -q 'no ray queries' "$tmp/devices.txt"
else
    check "lavapipe of Mesa $mesa: ray queries no" grep -Eq '^0 .* cpu .* no +llvmpipe' "$tmp/devices.txt"
    check "... saying it lacks VK_KHR_ray_query" grep -q '^device 0: no ray queries: it lacks VK_KHR_ray_query' "$tmp/devices.txt"
fi
check "gonio --version" sh -c "'$G' --version | grep -q '^gonio '"
for c in render info devices diff bench; do
    check "$c --help" sh -c "'$G' $c --help | grep -q usage"
done

# ---- bad usage (exit 2) and bad input (exit 1, no output) --------------------------------
check_fails "unknown command" 2 "$G" frobnicate
check_fails "unknown flag" 2 "$G" render $C -o "$tmp/x.exr" --frob
check_fails "bad --spp" 2 "$G" render $C -o "$tmp/x.exr" --spp zero
check_fails "bad --size" 2 "$G" render $C -o "$tmp/x.exr" --size 0x10
check_fails "bad --mode" 2 "$G" render $C -o "$tmp/x.exr" --mode bogus
check_fails "missing value" 2 "$G" render $C -o
check_fails "no output" 2 "$G" render $C
check_fails "missing scene" 1 "$G" render "$tmp/nope.gltf" -o "$tmp/x.exr" --quiet
check "missing scene: message names the file" grep -q "nope.gltf" "$tmp/last"
check_fails "unwritable output" 1 "$G" render $C -o /nonexistent/dir/x.exr --quiet
check "unwritable output: message names the path" grep -q "/nonexistent/dir/x.exr" "$tmp/last"
check_fails "camera out of range" 1 "$G" render $C -o "$tmp/x.exr" --camera 9 --quiet
check "no output after failures" test ! -e "$tmp/x.exr"

# Tiny glTF files made here: an empty scene, NaN and huge positions. Vertex colours (glTF
# COLOR_0) multiply the base colour: a triangle painted red through COLOR_0 (float RGB, or
# normalised unsigned-byte RGBA) under a white material renders exactly like the same
# triangle with a red base colour, in every mode that shows it.
python3 - "$tmp" <<'PY'
import sys
import gltf_fixture as gf
out = sys.argv[1]
def triangle(name, x0=0.0, base=None, colour=None):
    """(x0, 0, 0), (1, 0, 0), (0, 1, 0), its bounds as if x0 were 0; a material of the base
    colour (RGB) where given, and colour(g), COLOR_0's accessor"""
    g = gf.Gltf()
    prim = {"attributes": {"POSITION": g.accessor([x0, 0, 0, 1, 0, 0, 0, 1, 0], "VEC3", min=[0, 0, 0], max=[1, 1, 0])}}
    if base:
        prim["material"] = g.material({"pbrMetallicRoughness": {"baseColorFactor": base + [1], "metallicFactor": 0}})
    if colour:
        prim["attributes"]["COLOR_0"] = colour(g)
    g.scene([g.node(mesh=g.mesh(prim))])
    g.write(f"{out}/{name}.gltf")
triangle("ok")
triangle("nan", float("nan"))
triangle("huge", 1e38)
g = gf.Gltf()
g.scene([])
g.write(out + "/empty.gltf")
triangle("col_base", base=[1, 0, 0])
triangle("col_f", base=[1, 1, 1], colour=lambda g: g.accessor([1, 0, 0] * 3, "VEC3"))
triangle("col_u8", base=[1, 1, 1], colour=lambda g: g.accessor([255, 0, 0, 255] * 3, "VEC4", gf.UNSIGNED_BYTE, normalized=True))
PY
# (the renders of the rest of this script, in one batch)
col_modes=()
for mode in albedo phong gouraud flat path; do
    case $mode in albedo | path) in_tier fast || continue ;; *) in_tier slow || continue ;; esac
    col_modes+=("$mode")
    for f in col_base col_f col_u8; do
        queue "$f-$mode" render "$tmp/$f.gltf" -o "$tmp/$f-$mode.exr" --mode $mode --size 24x24 --spp 2 --env 1 --ambient 1 --quiet
    done
done
T=scenes/teapot.gltf
queue s1 render $C -o "$tmp/s1.exr" --mode phong --spp 2 --size 32x32
queue s2 render $C -o "$tmp/s2.exr" --spp 2 --size 32x32
queue ok render "$tmp/ok.gltf" -o "$tmp/ok.exr" --size 16x16 --spp 1 --quiet
for bad in nan huge empty; do queue "$bad" render "$tmp/$bad.gltf" -o "$tmp/$bad.exr" --size 16x16 --spp 1 --quiet; done
queue amb0 render $T --mode phong -o "$tmp/amb0.exr" --spp 4 --size 48x48 --quiet
queue amb2 render $T --mode phong --ambient 0.2 -o "$tmp/amb2.exr" --spp 4 --size 48x48 --quiet
queue amb3 render $T --mode gouraud --ambient 0.2,0.2,0.2 -o "$tmp/amb3.exr" --spp 1 --size 48x48 --quiet
run_queue
# The summary line: seconds, spp and Mrays/s.
queued s1 >/dev/null
check "summary line" grep -Eq 'phong, 2 spp in [0-9.]+ s \([0-9.]+ Mrays/s' "$tmp/last"
queued s2 >/dev/null
check "summary line of the path tracer" grep -Eq 'path, 2 spp in [0-9.]+ s \([0-9.]+ M paths/s' "$tmp/last"
check_queued "a one-triangle file renders" 0 ok
for bad in nan huge empty; do
    rc=$(queued "$bad")
    if [ "$rc" = 1 ] && grep -q "$bad.gltf" "$tmp/last" && [ ! -e "$tmp/$bad.exr" ]; then pass
    else fail "$bad.gltf: expected exit 1, a message naming the file, no output (got $rc)"; cat "$tmp/last"; fi
done

# --ambient: the Phong model's global ambient light A adds A * ka to every lit pixel. The
# teapot's material says ka = 0.2 (its extras), so A = 0.2 adds exactly 0.04 where the
# teapot covers a pixel: the largest difference is 0.04, not more, not less.
check_queued "phong without ambient" 0 amb0
check_queued "phong with --ambient 0.2" 0 amb2
check "ambient adds at most A ka = 0.04" "$G" diff "$tmp/amb0.exr" "$tmp/amb2.exr" --max-error 0.0401
check_fails "ambient adds A ka = 0.04 somewhere" 1 "$G" diff "$tmp/amb0.exr" "$tmp/amb2.exr" --max-error 0.0399
check_queued "gouraud with --ambient" 0 amb3
check_fails "a negative --ambient is a usage error" 2 "$G" render $T --mode phong --ambient -1 -o "$tmp/x.exr" --quiet
# (the fast tier: albedo and path; the slow tier: phong, gouraud and flat; rendered in the
# batch above)
for mode in "${col_modes[@]}"; do
    for f in col_base col_f col_u8; do check_queued "COLOR_0: $f renders in $mode" 0 "$f-$mode"; done
    check "COLOR_0 float RGB = base colour ($mode)" "$G" diff "$tmp/col_f-$mode.exr" "$tmp/col_base-$mode.exr" --max-error 1e-6
    check "COLOR_0 unorm8 RGBA = base colour ($mode)" "$G" diff "$tmp/col_u8-$mode.exr" "$tmp/col_base-$mode.exr" --max-error 1e-6
done
in_tier fast && check_fails "and the red is there: white differs" 1 "$G" diff "$tmp/col_f-albedo.exr" "$tmp/ok.exr" --max-error 0.5
finish
