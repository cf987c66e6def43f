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
        check "render $s $aov" "$G" render "$tmp/$s.gltf" -o "$tmp/$s-$aov.exr" --mode $aov \
            --spp 1 --size 96x96 --camera 0 --quiet
    done
done
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
check "no temporary files left" sh -c "! ls -a '$tmp' | grep -q tmp-"
for m in normal albedo depth cost phong; do
    check "mode $m renders" "$G" render $C -o "$tmp/m-$m.exr" --mode $m --spp 2 --size 32x32 --quiet
done
# Same command, same image, bit for bit.
check "render again" "$G" render $C -o "$tmp/c2.exr" --spp 4 --size 64x64 --aov normal,albedo,depth --seed 7 --quiet
check "deterministic: identical pixels" "$G" diff "$tmp/c.exr" "$tmp/c2.exr" --max-error 0 --quiet
check "render with another seed" "$G" render $C -o "$tmp/c3.exr" --spp 4 --size 64x64 --seed 8 --quiet
check_fails "another seed gives other pixels" 1 "$G" diff "$tmp/c.exr" "$tmp/c3.exr" --max-error 0 --quiet
# The summary line: seconds, spp and Mrays/s.
"$G" render $C -o "$tmp/s.exr" --mode phong --spp 2 --size 32x32 2>"$tmp/summary.txt"
check "summary line" grep -Eq 'phong, 2 spp in [0-9.]+ s \([0-9.]+ Mrays/s' "$tmp/summary.txt"
"$G" render $C -o "$tmp/s.exr" --spp 2 --size 32x32 2>"$tmp/summary.txt"
check "summary line of the path tracer" grep -Eq 'path, 2 spp in [0-9.]+ s \([0-9.]+ M paths/s' "$tmp/summary.txt"

check "gonio info" sh -c "'$G' info $C >'$tmp/info.txt'"
for f in triangles meshes materials lights 'bvh nodes' 'bvh depth' 'sah cost' 'bvh build'; do
    check "info prints $f" grep -q "$f" "$tmp/info.txt"
done
check "gonio devices lists lavapipe" sh -c "'$G' devices | grep -q llvmpipe"
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

# Tiny glTF files made here: an empty scene, NaN and huge positions.
b64() { printf "$1" | base64 -w0; }
tri_gltf() { # tri_gltf FILE BUFFER_BYTES_PRINTF
    cat >"$1" <<EOF
{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
 "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
 "bufferViews":[{"buffer":0,"byteLength":36}],
 "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,$(b64 "$2")"}]}
EOF
}
one='\000\000\200\077'; zero='\000\000\000\000'; nan='\000\000\300\177'; huge='\231\166\226\176'
tri_gltf "$tmp/ok.gltf" "$zero$zero$zero$one$zero$zero$zero$one$zero"
tri_gltf "$tmp/nan.gltf" "$nan$zero$zero$one$zero$zero$zero$one$zero"
tri_gltf "$tmp/huge.gltf" "$huge$zero$zero$one$zero$zero$zero$one$zero"
echo '{"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0}' >"$tmp/empty.gltf"
check "a one-triangle file renders" "$G" render "$tmp/ok.gltf" -o "$tmp/ok.exr" --size 16x16 --spp 1 --quiet
for bad in nan huge empty; do
    "$G" render "$tmp/$bad.gltf" -o "$tmp/$bad.exr" --size 16x16 --spp 1 --quiet >"$tmp/out" 2>&1
    rc=$?
    if [ $rc = 1 ] && grep -q "$bad.gltf" "$tmp/out" && [ ! -e "$tmp/$bad.exr" ]; then pass
    else fail "$bad.gltf: expected exit 1, a message naming the file, no output (got $rc)"; cat "$tmp/out"; fi
done

# --ambient: the Phong model's global ambient light A adds A * ka to every lit pixel. The
# teapot's material says ka = 0.2 (its extras), so A = 0.2 adds exactly 0.04 where the
# teapot covers a pixel: the largest difference is 0.04, not more, not less.
T=scenes/teapot.gltf
check "phong without ambient" "$G" render $T --mode phong -o "$tmp/amb0.exr" --spp 4 --size 48x48 --quiet
check "phong with --ambient 0.2" "$G" render $T --mode phong --ambient 0.2 -o "$tmp/amb2.exr" --spp 4 --size 48x48 --quiet
check "ambient adds at most A ka = 0.04" "$G" diff "$tmp/amb0.exr" "$tmp/amb2.exr" --max-error 0.0401
check_fails "ambient adds A ka = 0.04 somewhere" 1 "$G" diff "$tmp/amb0.exr" "$tmp/amb2.exr" --max-error 0.0399
check "gouraud with --ambient" "$G" render $T --mode gouraud --ambient 0.2,0.2,0.2 -o "$tmp/amb3.exr" --spp 1 --size 48x48 --quiet
check_fails "a negative --ambient is a usage error" 2 "$G" render $T --mode phong --ambient -1 -o "$tmp/x.exr" --quiet
# Vertex colours (glTF COLOR_0) multiply the base colour: a triangle painted red through
# COLOR_0 (float RGB, or normalised unsigned-byte RGBA) under a white material renders
# exactly like the same triangle with a red base colour, in every mode that shows it.
col_gltf() { # col_gltf FILE BASE_RGB COLOR_ATTRIBUTE_JSON COLOR_ACCESSOR_JSON COLOR_BYTES_PRINTF COLOR_BYTE_LENGTH
    cat >"$1" <<EOF
{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
 "materials":[{"pbrMetallicRoughness":{"baseColorFactor":[$2,1],"metallicFactor":0}}],
 "meshes":[{"primitives":[{"attributes":{"POSITION":0$3},"material":0}]}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}$4],
 "bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":$6}],
 "buffers":[{"byteLength":$((36 + $6)),"uri":"data:application/octet-stream;base64,$(b64 "$zero$zero$zero$one$zero$zero$zero$one$zero$5")"}]}
EOF
}
red_f="$one$zero$zero"; red_u8='\377\000\000\377'
col_gltf "$tmp/col_base.gltf" "1,0,0" "" "" "$zero" 4
col_gltf "$tmp/col_f.gltf" "1,1,1" ',"COLOR_0":1' \
    ',{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}' "$red_f$red_f$red_f" 36
col_gltf "$tmp/col_u8.gltf" "1,1,1" ',"COLOR_0":1' \
    ',{"bufferView":1,"componentType":5121,"normalized":true,"count":3,"type":"VEC4"}' "$red_u8$red_u8$red_u8" 12
for mode in albedo phong gouraud flat path; do
    for f in col_base col_f col_u8; do
        check "COLOR_0: $f renders in $mode" "$G" render "$tmp/$f.gltf" -o "$tmp/$f-$mode.exr" --mode $mode \
            --size 24x24 --spp 2 --env 1 --ambient 1 --quiet
    done
    check "COLOR_0 float RGB = base colour ($mode)" "$G" diff "$tmp/col_f-$mode.exr" "$tmp/col_base-$mode.exr" --max-error 1e-6
    check "COLOR_0 unorm8 RGBA = base colour ($mode)" "$G" diff "$tmp/col_u8-$mode.exr" "$tmp/col_base-$mode.exr" --max-error 1e-6
done
check_fails "and the red is there: white differs" 1 "$G" diff "$tmp/col_f-albedo.exr" "$tmp/ok.exr" --max-error 0.5
finish
