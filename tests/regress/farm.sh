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
# The whole renders in processes of their own; the tiles, crops and seeds in one batch.
"$G" render $S "${common[@]}" --spp 5 --aov variance,depth -o "$tmp/whole.exr"
# A 3x3 tiling with uneven tiles (66 = 22 + 22 + 22, 48 = 16 + 17 + 15).
xs=(0 22 44 66) ys=(0 16 33 48) tiles=()
for j in 0 1 2; do for i in 0 1 2; do
    t="$tmp/tile_$i$j.exr"
    queue "tile$i$j" render $S "${common[@]}" --spp 5 --aov variance,depth \
        --crop "${xs[i]},${ys[j]},${xs[i + 1]},${ys[j + 1]}" -o "$t"
    tiles+=("$t")
done; done
# Fractions as pbrt's cropwindow: ceil(0.5 * 66) = 33, ceil(0.25 * 48) = 12.
queue frac render $S "${common[@]}" --spp 5 --aov variance,depth --crop 0.5,0.25,1.0,1.0 -o "$tmp/frac.exr"
# A local mode too (one sample a dispatch, another kernel).
"$G" render $S "${common[@]}" --mode phong --spp 3 -o "$tmp/phong.exr"
queue phong_crop render $S "${common[@]}" --mode phong --spp 3 --crop 5,7,40,30 -o "$tmp/phong_crop.exr"
# The other sampler (the default is Sobol, docs/path-tracing.md): its tiles too.
"$G" render $S "${common[@]}" --spp 5 --sampler independent -o "$tmp/whole_ind.exr"
queue ind_crop render $S "${common[@]}" --spp 5 --sampler independent --crop 5,7,40,30 -o "$tmp/ind_crop.exr"
# Tiles x seeds: 2 tiles x 2 seeds merged = 2 whole renders of those seeds merged.
for s in 1 2; do
    queue "w$s" render $S "${common[@]}" --spp 4 --seed $s --aov variance -o "$tmp/w$s.exr"
    queue "a$s" render $S "${common[@]}" --spp 4 --seed $s --aov variance --crop 0,0,66,20 -o "$tmp/a$s.exr"
    queue "b$s" render $S "${common[@]}" --spp 4 --seed $s --aov variance --crop 0,20,66,48 -o "$tmp/b$s.exr"
done
run_queue
for j in 0 1 2; do for i in 0 1 2; do check_queued "tile $i,$j renders" 0 "tile$i$j"; done; done
exrheader "$tmp/tile_21.exr" >"$tmp/h21"
has "$tmp/h21" "dataWindow (type box2i): (44 16) - (65 32)"
has "$tmp/h21" "displayWindow (type box2i): (0 0) - (65 47)"
same "$tmp/whole.exr" "$tmp/tile_21.exr" "a tile's pixels are the whole render's"
check "the 3x3 tiles merge" "$G" merge "${tiles[@]}" -o "$tmp/tiled.exr"
exrheader "$tmp/tiled.exr" >"$tmp/ht"
has "$tmp/ht" "dataWindow (type box2i): (0 0) - (65 47)"
same "$tmp/whole.exr" "$tmp/tiled.exr" "the merged 3x3 tiling equals the whole render"
same "$tmp/tiled.exr" "$tmp/whole.exr" "... and covers all of it"
check_queued "a crop in fractions" 0 frac
exrheader "$tmp/frac.exr" >"$tmp/hf"
has "$tmp/hf" "dataWindow (type box2i): (33 12) - (65 47)"
same "$tmp/whole.exr" "$tmp/frac.exr" "a fractional crop's pixels are the whole render's"
same "$tmp/phong.exr" "$tmp/phong_crop.exr" "a phong crop's pixels are the whole render's"
same "$tmp/whole_ind.exr" "$tmp/ind_crop.exr" "--sampler independent: a crop's pixels are the whole render's"
check_fails "the samplers' images differ" 1 "$G" diff "$tmp/whole.exr" "$tmp/whole_ind.exr" --max-error 0
"$G" merge "$tmp/w1.exr" "$tmp/w2.exr" -o "$tmp/wm.exr"
check "tiles x seeds merge" "$G" merge "$tmp/a1.exr" "$tmp/b2.exr" "$tmp/b1.exr" "$tmp/a2.exr" -o "$tmp/tm.exr"
same "$tmp/wm.exr" "$tmp/tm.exr" "tiles x seeds merged equal the seeds' whole renders merged"
exrheader "$tmp/tm.exr" >"$tmp/htm"
has "$tmp/htm" 'gonio:seeds (type string): "1,2"'
has "$tmp/htm" "gonio:spp (type int): 8"
has "$tmp/htm" 'gonio:sampler (type string): "sobol"'
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
"$G" render $S "${r[@]}" --spp 40 --crop 8,4,31,25 -o "$tmp/c40.exr"
# (the renders that resume, and those refused, in one batch)
queue r64 render $S "${r[@]}" --spp 64 --resumable -o "$tmp/r64.exr"
queue r64_128 render $S "${r[@]}" --spp 128 --resume "$tmp/r64.exr" -o "$tmp/r64_128.exr"
# A crop resumes too, and in an odd split (13 + 27), even with --half for the means.
queue c13 render $S "${r[@]}" --spp 13 --crop 8,4,31,25 --resumable --half -o "$tmp/c13.exr"
queue c13_40 render $S "${r[@]}" --spp 40 --crop 8,4,31,25 --resume "$tmp/c13.exr" -o "$tmp/c13_40.exr"
# ... and with the other sampler; a file of one sampler does not resume with the other.
queue i64 render $S "${r[@]}" --spp 64 --sampler independent --resumable -o "$tmp/i64.exr"
queue i64_128 render $S "${r[@]}" --spp 128 --sampler independent --resume "$tmp/i64.exr" -o "$tmp/i64_128.exr"
queue i128 render $S "${r[@]}" --spp 128 --sampler independent -o "$tmp/i128.exr"
queue sampler render $S "${r[@]}" --spp 128 --resume "$tmp/i64.exr" -o "$tmp/x.exr"
queue seed render $S "${r[@]/7/8}" --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
queue depth render $S "${r[@]}" --max-depth 3 --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
queue camera render $S "${r[@]}" --fov 30 --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
queue region render $S "${r[@]}" --crop 0,0,10,10 --spp 128 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
queue nosums render $S "${r[@]}" --spp 256 --resume "$tmp/r128.exr" -o "$tmp/x.exr"
queue fewer render $S "${r[@]}" --spp 64 --resume "$tmp/r64.exr" -o "$tmp/x.exr"
queue missing render $S "${r[@]}" --spp 64 --resume "$tmp/none.exr" -o "$tmp/x.exr"
run_queue
check_queued "64 spp, resumable" 0 r64
exrheader "$tmp/r64.exr" >"$tmp/h64"
has "$tmp/h64" "sum.R, 32-bit floating-point"
check_queued "resumed to 128" 0 r64_128
same "$tmp/r128.exr" "$tmp/r64_128.exr" "64 + 64 resumed equals 128 in one run"
exrheader "$tmp/r64_128.exr" >"$tmp/hr"
has "$tmp/hr" "gonio:spp (type int): 128"
check_queued "a crop, resumable" 0 c13
check_queued "a crop resumed" 0 c13_40
same "$tmp/c40.exr" "$tmp/c13_40.exr" "a crop's 13 + 27 resumed equals its 40 in one run"
check_queued "--sampler independent: resumed to 128" 0 i64_128
same "$tmp/i128.exr" "$tmp/i64_128.exr" "--sampler independent: 64 + 64 resumed equals 128 in one run"
has "$tmp/h64" 'gonio:sampler (type string): "sobol"'
check_queued "resume: another sampler is refused" 1 sampler
has "$tmp/last" "independent sampler's, this render's the sobol one's"
check_queued "resume: another seed is refused" 1 seed
has "$tmp/last" "seed"
check_queued "resume: another max depth is refused" 1 depth
has "$tmp/last" "gonio:max-depth differs"
check_queued "resume: another camera is refused" 1 camera
has "$tmp/last" "gonio:camera differs"
check_queued "resume: another region is refused" 1 region
has "$tmp/last" "region"
check_queued "resume: a file without sums is refused" 1 nosums
has "$tmp/last" "no channel 'sum.R'"
check_queued "resume: no more samples than the file is refused" 1 fewer
check_queued "resume: a missing file" 1 missing
has "$tmp/last" "none.exr"
[ ! -e "$tmp/x.exr" ] && pass || fail "a refused resume left an output"

# SIGTERM (a scheduler's pre-emption) writes a resumable file; resuming it gives the render
# of the total. The render is long enough to be running when the signal comes.
"$G" render $S --size 40x30 --seed 3 --spp 4000 -o "$tmp/term.exr" 2>"$tmp/term.err" &
pid=$!
check "the render to pre-empt is in its passes" wait_for "$tmp/term.err" '^gonio: *[0-9]*%'
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

# ---- animation -----------------------------------------------------------------------------
# anim FILE NODE INTERP TIMES VALUES: a red 0.4 x 0.4 square (node 0, at the origin) seen by
# an orthographic camera (node 1, at z = 5, xmag 2, ymag 1), one animation whose sampler
# (INTERP, key TIMES, output VALUES: x of a VEC3 each, y = 0, z = 0 or the camera's 5)
# drives NODE's translation.
anim() {
    python3 - "$@" <<'PY'
import sys
import gltf_fixture as gf
out, node, interp = sys.argv[1], int(sys.argv[2]), sys.argv[3]
times, values = [float(t) for t in sys.argv[4].split()], [float(v) for v in sys.argv[5].split()]
g = gf.Gltf()
red = g.material({"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}, "doubleSided": True})
square = g.primitive([-0.2, -0.2, 0, 0.2, -0.2, 0, 0.2, 0.2, 0, -0.2, 0.2, 0], indices=gf.QUAD_INDICES, material=red,
                     index_type=gf.UNSIGNED_SHORT)
g.scene([g.node(mesh=g.mesh(square)), g.node(camera=g.orthographic(2, 1), translation=[0, 0, 5])])
key = g.accessor(times, "SCALAR")
moves = g.accessor([c for v in values for c in (v, 0, 5 if node == 1 else 0)], "VEC3")
g.add("animations", {"name": "move", "samplers": [{"input": key, "output": moves, "interpolation": interp}],
                     "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]})
g.write(out)
PY
}
# at FILE.exr X: the red square's centre in the image is where world x = X maps
# (200 px over 4 units: pixel 50 X + 100), within a pixel.
at() {
    local c
    c=$("$T" stats "$1" | awk '{ print ($8 + $10 + 1) / 2 }')
    if awk -v c="$c" -v x="$2" 'BEGIN { w = 50 * x + 100; exit !(c - w < 1 && w - c < 1) }'; then pass
    else fail "$1: the square is centred at pixel $c, expected $(awk -v x="$2" 'BEGIN { print 50 * x + 100 }') (x = $2)"; fi
}
a=(--size 200x100 --mode albedo --spp 1 --quiet)
anim "$tmp/linear.gltf" 0 LINEAR "0 2" "-1 1"
check "--frames renders one file a frame" "$G" render "$tmp/linear.gltf" "${a[@]}" --fps 4 --frames 0-8 -o "$tmp/lin_%02d.exr"
at "$tmp/lin_00.exr" -1     # frame 0, t = 0
at "$tmp/lin_03.exr" -0.25  # frame 3, t = 0.75: -1 + 2 (0.75 / 2)
at "$tmp/lin_08.exr" 1      # the last frame, t = 2
exrheader "$tmp/lin_03.exr" >"$tmp/hl"
has "$tmp/hl" "gonio:frame (type int): 3"
has "$tmp/hl" "gonio:time (type double): 0.75"
# at_time FILE T X: FILE rendered at time T shows the square at X (the renders in one batch).
at_n=0
at_time() { at_n=$((at_n + 1)); queue "at$at_n" render "$1" "${a[@]}" --at "$2" -o "$tmp/at$at_n.exr"; after_queue at_checks $at_n "$3"; }
at_checks() { check_queued "--at: render $1" 0 "at$1"; at "$tmp/at$1.exr" "$2"; }
at_time "$tmp/linear.gltf" 5 1  # after the last key: its value
anim "$tmp/step.gltf" 0 STEP "0 1 2" "-1 0.5 1"
at_time "$tmp/step.gltf" 0.99 -1
at_time "$tmp/step.gltf" 1.5 0.5
# CUBICSPLINE: keys (in-tangent, value, out-tangent) = (0, -1, 1.5) at t 0 and (2, 1, 0) at
# t 2; at t = 0.5, u = 0.25, td = 2: the spec's Hermite form, computed here.
anim "$tmp/cubic.gltf" 0 CUBICSPLINE "0 2" "0 -1 1.5 2 1 0"
want=$(awk 'BEGIN { u = 0.25; td = 2; u2 = u * u; u3 = u2 * u;
    print (2*u3 - 3*u2 + 1) * -1 + td * (u3 - 2*u2 + u) * 1.5 + (-2*u3 + 3*u2) * 1 + td * (u3 - u2) * 2 }')
at_time "$tmp/cubic.gltf" 0.5 "$want"
# The camera animates: it moves to x = 1 over a second; at 0.5 s the square is 0.5 left.
anim "$tmp/camera.gltf" 1 LINEAR "0 1" "0 1"
at_time "$tmp/camera.gltf" 0.5 -0.5
run_queue
check_fails "--frames needs a pattern" 2 "$G" render "$tmp/linear.gltf" "${a[@]}" --frames 0-2 -o "$tmp/x.exr"
check_fails "--frames A-B with B < A" 2 "$G" render "$tmp/linear.gltf" "${a[@]}" --frames 3-2 -o "$tmp/x%d.exr"
check_fails "--frame and --at" 2 "$G" render "$tmp/linear.gltf" "${a[@]}" --frame 1 --at 2 -o "$tmp/x.exr"
anim "$tmp/short.gltf" 0 LINEAR "0 2" "-1"
check_fails "a sampler with too few values is refused" 1 "$G" render "$tmp/short.gltf" "${a[@]}" --at 1 -o "$tmp/x.exr"
has "$tmp/last" "short.gltf"

finish
