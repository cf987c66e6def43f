#!/usr/bin/env bash
# farm.sh: the pieces a render farm splits work into, each checked bit for bit against the
# render it stands for: --crop tiles (their EXR windows read by OpenEXR's exrheader) merged
# back, tiles x seeds, --resume and SIGTERM's resumable file, and glTF animation sampled
# at a time against positions computed here from the spec's formulas.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
T=$TESTTOOL
S=scenes/cornell.gltf
common=(--size 66x48 --quiet)

# same WHOLE PART: every pixel of PART equals WHOLE's at its place, bit for bit.
same() { check "$3" "$T" same "$1" "$2"; }
has() { if grep -qF -- "$2" "$1"; then pass; else fail "$1 lacks '$2': $(head -c 600 "$1")"; fi; }

# ---- tiles ---------------------------------------------------------------------------------
"$G" render $S "${common[@]}" --spp 5 --aov variance,depth -o "$tmp/whole.exr"
# A 3x3 tiling with uneven tiles (66 = 22 + 22 + 22, 48 = 16 + 17 + 15).
xs=(0 22 44 66) ys=(0 16 33 48) tiles=()
for j in 0 1 2; do for i in 0 1 2; do
    t="$tmp/tile_$i$j.exr"
    check "tile $i,$j renders" "$G" render $S "${common[@]}" --spp 5 --aov variance,depth \
        --crop "${xs[i]},${ys[j]},${xs[i + 1]},${ys[j + 1]}" -o "$t"
    tiles+=("$t")
done; done
exrheader "$tmp/tile_21.exr" >"$tmp/h21"
has "$tmp/h21" "dataWindow (type box2i): (44 16) - (65 32)"
has "$tmp/h21" "displayWindow (type box2i): (0 0) - (65 47)"
same "$tmp/whole.exr" "$tmp/tile_21.exr" "a tile's pixels are the whole render's"
check "the 3x3 tiles merge" "$G" merge "${tiles[@]}" -o "$tmp/tiled.exr"
exrheader "$tmp/tiled.exr" >"$tmp/ht"
has "$tmp/ht" "dataWindow (type box2i): (0 0) - (65 47)"
same "$tmp/whole.exr" "$tmp/tiled.exr" "the merged 3x3 tiling equals the whole render"
same "$tmp/tiled.exr" "$tmp/whole.exr" "... and covers all of it"
# Fractions as pbrt's cropwindow: ceil(0.5 * 66) = 33, ceil(0.25 * 48) = 12.
check "a crop in fractions" "$G" render $S "${common[@]}" --spp 5 --aov variance,depth \
    --crop 0.5,0.25,1.0,1.0 -o "$tmp/frac.exr"
exrheader "$tmp/frac.exr" >"$tmp/hf"
has "$tmp/hf" "dataWindow (type box2i): (33 12) - (65 47)"
same "$tmp/whole.exr" "$tmp/frac.exr" "a fractional crop's pixels are the whole render's"
# A local mode too (one sample a dispatch, another kernel).
"$G" render $S "${common[@]}" --mode phong --spp 3 -o "$tmp/phong.exr"
"$G" render $S "${common[@]}" --mode phong --spp 3 --crop 5,7,40,30 -o "$tmp/phong_crop.exr"
same "$tmp/phong.exr" "$tmp/phong_crop.exr" "a phong crop's pixels are the whole render's"

# Tiles x seeds: 2 tiles x 2 seeds merged = 2 whole renders of those seeds merged.
for s in 1 2; do
    "$G" render $S "${common[@]}" --spp 4 --seed $s --aov variance -o "$tmp/w$s.exr"
    "$G" render $S "${common[@]}" --spp 4 --seed $s --aov variance --crop 0,0,66,20 -o "$tmp/a$s.exr"
    "$G" render $S "${common[@]}" --spp 4 --seed $s --aov variance --crop 0,20,66,48 -o "$tmp/b$s.exr"
done
"$G" merge "$tmp/w1.exr" "$tmp/w2.exr" -o "$tmp/wm.exr"
check "tiles x seeds merge" "$G" merge "$tmp/a1.exr" "$tmp/b2.exr" "$tmp/b1.exr" "$tmp/a2.exr" -o "$tmp/tm.exr"
same "$tmp/wm.exr" "$tmp/tm.exr" "tiles x seeds merged equal the seeds' whole renders merged"
exrheader "$tmp/tm.exr" >"$tmp/htm"
has "$tmp/htm" 'gonio:seeds (type string): "1,2"'
has "$tmp/htm" "gonio:spp (type int): 8"
check_fails "a hole between tiles is refused" 1 "$G" merge "$tmp/tile_00.exr" "$tmp/tile_20.exr" -o "$tmp/x.exr"
has "$tmp/last" "leave a hole"
check_fails "overlapping tiles of one seed are refused" 1 "$G" merge "$tmp/tile_00.exr" "$tmp/whole.exr" -o "$tmp/x.exr"
has "$tmp/last" "seed 0"
check_fails "an empty crop is a usage error" 2 "$G" render $S "${common[@]}" --crop 10,10,10,20 -o "$tmp/x.exr"
check_fails "a crop outside the image is a usage error" 2 "$G" render $S "${common[@]}" --crop 0,0,67,10 -o "$tmp/x.exr"
check_fails "a malformed crop is a usage error" 2 "$G" render $S "${common[@]}" --crop 0,0,1.5,1 -o "$tmp/x.exr"
[ ! -e "$tmp/x.exr" ] && pass || fail "a refused render left an output"

# ---- resume --------------------------------------------------------------------------------
# 64 + 64 = 128, with AOVs and the variance: every channel bit for bit.
r=(--size 40x30 --quiet --aov normal,depth,variance --seed 7)
"$G" render $S "${r[@]}" --spp 128 -o "$tmp/r128.exr"
check "64 spp, resumable" "$G" render $S "${r[@]}" --spp 64 --resumable -o "$tmp/r64.exr"
exrheader "$tmp/r64.exr" >"$tmp/h64"
has "$tmp/h64" "sum.R, 32-bit floating-point"
check "resumed to 128" "$G" render $S "${r[@]}" --spp 128 --resume "$tmp/r64.exr" -o "$tmp/r64_128.exr"
same "$tmp/r128.exr" "$tmp/r64_128.exr" "64 + 64 resumed equals 128 in one run"
exrheader "$tmp/r64_128.exr" >"$tmp/hr"
has "$tmp/hr" "gonio:spp (type int): 128"
# A crop resumes too, and in an odd split (13 + 27), even with --half for the means.
"$G" render $S "${r[@]}" --spp 40 --crop 8,4,31,25 -o "$tmp/c40.exr"
"$G" render $S "${r[@]}" --spp 13 --crop 8,4,31,25 --resumable --half -o "$tmp/c13.exr"
check "a crop resumed" "$G" render $S "${r[@]}" --spp 40 --crop 8,4,31,25 --resume "$tmp/c13.exr" -o "$tmp/c13_40.exr"
same "$tmp/c40.exr" "$tmp/c13_40.exr" "a crop's 13 + 27 resumed equals its 40 in one run"
check_fails "resume: another seed is refused" 1 "$G" render $S "${r[@]/7/8}" --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
has "$tmp/last" "seed"
check_fails "resume: another max depth is refused" 1 "$G" render $S "${r[@]}" --max-depth 3 --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
has "$tmp/last" "gonio:max-depth differs"
check_fails "resume: another camera is refused" 1 "$G" render $S "${r[@]}" --fov 30 --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
has "$tmp/last" "gonio:camera differs"
check_fails "resume: another region is refused" 1 "$G" render $S "${r[@]}" --crop 0,0,10,10 --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
has "$tmp/last" "region"
check_fails "resume: a file without sums is refused" 1 "$G" render $S "${r[@]}" --spp 256 --resume "$tmp/r128.exr" -o "$tmp/x.exr"
has "$tmp/last" "no channel 'sum.R'"
check_fails "resume: no more samples than the file is refused" 1 "$G" render $S "${r[@]}" --spp 64 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
check_fails "resume: a missing file" 1 "$G" render $S "${r[@]}" --spp 64 --resume "$tmp/none.exr" -o "$tmp/x.exr"
has "$tmp/last" "none.exr"
[ ! -e "$tmp/x.exr" ] && pass || fail "a refused resume left an output"

# SIGTERM (a scheduler's pre-emption) writes a resumable file; resuming it gives the render
# of the total. The render is long enough to be running when the signal comes.
"$G" render $S --size 40x30 --seed 3 --spp 4000 --quiet -o "$tmp/term.exr" &
pid=$!
sleep 2
kill -TERM $pid
wait $pid
st=$?
if [ -e "$tmp/term.exr" ]; then
    pass
    spp=$(exrheader "$tmp/term.exr" | sed -n 's/^gonio:spp (type int): //p')
    if [ -n "$spp" ] && [ "$spp" -gt 0 ] && [ "$spp" -lt 4000 ]; then pass; else fail "SIGTERM's file has spp '$spp' (exit $st)"; fi
    total=$((spp + 37))
    check "SIGTERM's file resumes" "$G" render $S --size 40x30 --seed 3 --spp $total --quiet --resume "$tmp/term.exr" -o "$tmp/term2.exr"
    "$G" render $S --size 40x30 --seed 3 --spp $total --quiet -o "$tmp/term1.exr"
    same "$tmp/term1.exr" "$tmp/term2.exr" "pre-empted and resumed equals one run of the total"
else
    fail "SIGTERM left no output (exit $st)"
fi

finish
