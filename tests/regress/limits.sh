#!/usr/bin/env bash
# limits.sh: the device's limits (src/core/gpu.c: gpu_storage_limit, gpu_max_texels,
# gpu_max_groups). A render above the storage-buffer range is rendered in bands, bit for bit
# the render in one piece (or in other bands); the AOV and squares buffers exist only when
# asked for; Gouraud's vertex pass dispatches in rows of work groups; what cannot be done at
# all is refused with the limit named. GONIO_MAX_BUFFER_BYTES, GONIO_MAX_WORKGROUPS and
# GONIO_MAX_TEXELS lower the limits so that small renders reach the same code.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
T=$TESTTOOL
S=scenes/cornell.gltf
same() { check "$3" "$T" same "$1" "$2"; }
has() { if grep -qF -- "$2" "$1"; then pass; else fail "$1 lacks '$2': $(head -c 600 "$1")"; fi; }
lacks() { if grep -qF -- "$2" "$1"; then fail "$1 has '$2'"; else pass; fi; }

# ---- above lavapipe's maxStorageBufferRange (128 MiB): 3000x3000 x 16 bytes = 144 MB -----
# The validation layer is on (tests/run.sh): a buffer bound beyond the range fails the run.
# (slow: two 9-megapixel renders; the fast tier's bands below take the same path with the
# limit lowered, on small images)
if in_tier slow; then
    "$G" render $S --mode phong --spp 1 --size 3000x3000 -o "$tmp/big.exr" 2>"$tmp/big.log"
    check "a 3000x3000 render passes validation" test $? = 0
    has "$tmp/big.log" "3000x3000 rendered in 2 bands of 1504 rows"
    has "$tmp/big.log" "maxStorageBufferRange"
    GONIO_MAX_BUFFER_BYTES=40000000 "$G" render $S --mode phong --spp 1 --size 3000x3000 \
        -o "$tmp/big7.exr" 2>"$tmp/big7.log"
    check "the same render in smaller bands passes" test $? = 0
    has "$tmp/big7.log" "in 4 bands of 752 rows" # 833 rows fit: 4 of 750, whole tiles
    same "$tmp/big.exr" "$tmp/big7.exr" "2 bands and 4 bands give the same bits"
fi

in_tier fast || { finish; exit; }

# The renders below run in one batch (lib.sh: queue), each with its limits as NAME=value
# words of its own line; a line's log is $tmp/queue/ID.log.
L() { echo "$tmp/queue/$1.log"; }
l=(--spp 40 --size 96x80 --aov normal,albedo,depth,variance --resumable)
p=("${l[@]}" --quiet)
c=(--crop 10,7,90,61)
gr=(--mode gouraud --spp 1 --size 64x64 --quiet)
queue whole render $S "${p[@]}" -o "$tmp/whole.exr"
queue banded GONIO_MAX_BUFFER_BYTES=20000 render $S "${l[@]}" -o "$tmp/banded.exr"
queue cw render $S "${p[@]}" "${c[@]}" -o "$tmp/cw.exr"
queue cb GONIO_MAX_BUFFER_BYTES=9000 render $S "${p[@]}" "${c[@]}" -o "$tmp/cb.exr"
queue part render $S "${p[@]/40/16}" -o "$tmp/part.exr"
queue resumed GONIO_MAX_BUFFER_BYTES=20000 render $S "${p[@]}" --resume "$tmp/part.exr" -o "$tmp/resumed.exr"
queue timed GONIO_MAX_BUFFER_BYTES=20000 render $S --time 0.5 --size 96x80 --quiet -o "$tmp/timed.exr"
queue plain GONIO_DEBUG_BUFFERS=1 render $S --spp 1 --size 64x48 -o "$tmp/plain.exr"
queue depth GONIO_DEBUG_BUFFERS=1 render $S --spp 1 --size 64x48 --aov depth -o "$tmp/depth.exr"
queue var GONIO_DEBUG_BUFFERS=1 render $S --spp 2 --size 64x48 --aov variance -o "$tmp/var.exr"
queue novar render $S --spp 2 --size 64x48 --quiet -o "$tmp/novar.exr"
queue teapot teapot --level 8 -o "$tmp/teapot.gltf" # 2081 vertices: 33 groups of 64
queue g1 render "$tmp/teapot.gltf" "${gr[@]}" -o "$tmp/g1.exr"
# 8 groups a row: 5 rows of groups (and the image's 8x8 groups of 8x8 pixels still fit).
queue g8 GONIO_MAX_WORKGROUPS=8 render "$tmp/teapot.gltf" "${gr[@]}" -o "$tmp/g8.exr"
queue g5 GONIO_MAX_WORKGROUPS=5 render "$tmp/teapot.gltf" --mode gouraud --spp 1 --size 40x40 --quiet -o "$tmp/g5.exr"
queue gbig GONIO_MAX_BUFFER_BYTES=60000 render "$tmp/teapot.gltf" "${gr[@]}" -o "$tmp/gbig.exr"
queue pbig GONIO_MAX_BUFFER_BYTES=60000 render "$tmp/teapot.gltf" --mode phong --spp 1 --size 64x64 --quiet -o "$tmp/pbig.exr"
queue row GONIO_MAX_BUFFER_BYTES=1000 render $S --spp 1 --size 96x80 --quiet -o "$tmp/row.exr"
queue wide GONIO_MAX_WORKGROUPS=4 render $S --spp 1 --size 40x8 --quiet -o "$tmp/wide.exr"
queue texels GONIO_MAX_TEXELS=100 render $S --spp 1 --size 16x16 --quiet -o "$tmp/texels.exr"
A=${GONIO_ASSETS:-}/gltf/BoxTextured/glTF/BoxTextured.gltf
if [ -f "$A" ]; then
    # its one image is 256x256: 65,537 texels with the buffer's trailing zero
    queue box GONIO_MAX_TEXELS=65536 render "$A" --spp 1 --size 16x16 --quiet -o "$tmp/box.exr"
    queue box-fits GONIO_MAX_TEXELS=65537 render "$A" --spp 1 --size 16x16 --env 0 --quiet -o "$tmp/box-fits.exr"
fi
run_queue

# ---- bands forced on a small image: path, every AOV and the sums, several rounds ----------
check_queued "whole" 0 whole
check_queued "in bands" 0 banded
has "$(L banded)" "96x80 rendered in 20 bands of 4 rows: its 368640-byte AOV buffer exceeds the device's GONIO_MAX_BUFFER_BYTES (20000 bytes)"
same "$tmp/whole.exr" "$tmp/banded.exr" "bands give the whole render's pixels and AOVs"
for c in sum.R sum.A sum.normal.Y sum.depth.Z sum2.B; do
    "$T" pick "$tmp/whole.exr" $c "$tmp/w_$c.exr" && "$T" pick "$tmp/banded.exr" $c "$tmp/b_$c.exr"
    same "$tmp/w_$c.exr" "$tmp/b_$c.exr" "bands keep the exact sums ($c)"
done
# A crop in bands, and a banded render resumed from a render in one piece.
check_queued "crop whole" 0 cw
check_queued "crop in bands" 0 cb
same "$tmp/cw.exr" "$tmp/cb.exr" "a crop in bands is the crop in one piece"
check_queued "16 spp in one piece" 0 part
check_queued "resumed in bands" 0 resumed
same "$tmp/whole.exr" "$tmp/resumed.exr" "a render resumed in bands is the whole render"
# --time: every round goes through all bands, so the header's spp is every pixel's.
check_queued "--time in bands" 0 timed
spp=$(exrheader "$tmp/timed.exr" 2>/dev/null | sed -n 's/^gonio:spp (type int): //p')
check "--time in bands took samples" test "${spp:-0}" -ge 1
check "the same spp in one piece" "$G" render $S --spp "${spp:-1}" --size 96x80 --quiet -o "$tmp/untimed.exr"
same "$tmp/untimed.exr" "$tmp/timed.exr" "--time in bands: every pixel has the header's spp"

# ---- the AOV and squares buffers only when asked for -------------------------------------
has "$(L plain)" "buffers for 64x48: accum 49152, aov 16, squares 16 bytes"
has "$(L depth)" "buffers for 64x48: accum 49152, aov 147456, squares 16 bytes"
has "$(L var)" "buffers for 64x48: accum 49152, aov 16, squares 49152 bytes"
v=$("$T" at "$tmp/var.exr" variance.R 32 24)
check "the squares are summed (variance.R at 32,24 is $v)" awk -v v="$v" 'BEGIN { exit !(v > 0) }'
# Without the squares the colours are the same bits.
check_queued "render with variance" 0 novar
"$T" pick "$tmp/var.exr" R "$tmp/var_R.exr" && "$T" pick "$tmp/novar.exr" R "$tmp/novar_R.exr"
same "$tmp/var_R.exr" "$tmp/novar_R.exr" "the variance AOV changes no colour"

# ---- Gouraud's vertex pass in rows of work groups ------------------------------------------
check_queued "teapot" 0 teapot
check_queued "gouraud" 0 g1
check_queued "gouraud, 8 work groups a row" 0 g8
same "$tmp/g1.exr" "$tmp/g8.exr" "the vertex pass in rows of groups lights every vertex"
check_queued "more vertex groups than rows x columns is refused" 1 g5
has "$tmp/last" "the 2081 vertices need 33 work groups, more than this device dispatches (maxComputeWorkGroupCount 5 x 5)"
check_queued "vertex colours beyond a storage buffer: gouraud refused" 1 gbig
has "$tmp/last" "--mode gouraud: the 2081 vertices' colours need 66592 bytes, more than one storage buffer may hold on this device (GONIO_MAX_BUFFER_BYTES: 60000)"
check_queued "...while phong renders" 0 pbig

# ---- what cannot be done at all -------------------------------------------------------------
check_queued "a row beyond a storage buffer is refused" 1 row
has "$tmp/last" "a row of 96 pixels needs 1536 bytes of accumulation buffers, more than this device allows (GONIO_MAX_BUFFER_BYTES: 1000 bytes"
check "no output" test ! -e "$tmp/row.exr"
check_queued "a row wider than the work groups is refused" 1 wide
has "$tmp/last" "a row of 40 pixels needs 5 work groups, more than the 4 this device dispatches (maxComputeWorkGroupCount[0])"
check_queued "a scene beyond a texel buffer is refused" 1 texels
has "$tmp/last" "scenes/cornell.gltf: the vertices need"
has "$tmp/last" "more than the 100 of one texel buffer on this device (GONIO_MAX_TEXELS)"
if [ -f "$A" ]; then
    check_queued "textures beyond a texel buffer are refused" 1 box
    has "$tmp/last" "the 1 texture image(s) hold 65537 texels (the largest, image 0, is 256x256), more than the 65536"
    check_queued "...and fit at the limit" 0 box-fits
else
    echo "  skipped: BoxTextured (no \$GONIO_ASSETS)"
fi
finish
