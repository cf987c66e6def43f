#!/usr/bin/env bash
# instances.sh: meshes placed by instances (several nodes using one mesh, nested transforms
# with a non-uniform scale and a mirror, EXT_mesh_gpu_instancing, alpha-masked instances,
# instanced emitters as the only light, world geometry beside them) render like the same
# scene flattened, every placement a mesh of its own that the loader bakes into world space
# (tests/tool/instances.py writes both): the local modes to within rounding, the path
# tracer statistically (no bias, and no more noise than two seeds of the flattened scene
# differ by). Paths interrupted by the loop cap resume inside instances bit for bit; the
# Khronos SimpleInstancing sample renders like its flattened self; a wrong instance
# attribute is an error naming its JSON path.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
A=${GONIO_ASSETS:-}/gltf
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
python3 "$(dirname "$0")/../tool/instances.py" "$tmp" || { fail "scenes"; finish; exit; }
I=$tmp/inst.gltf F=$tmp/flat.gltf
V="--camera 0 --quiet"

# gonio info: what is placed and what is stored
"$G" info "$I" >"$tmp/info" 2>&1
check "info: instances" grep -q '^instances *19 of 4 mesh' "$tmp/info"
placed=$(awk '$1 == "triangles" {print $2}' "$tmp/info")
flat=$("$G" info "$F" | awk '$1 == "triangles" {print $2}')
check "info: the instances place the flattened scene's triangles ($placed, $flat)" test "$placed" = "$flat"
check "info: a top tree over them" grep -q 'top tree over 20 instances' "$tmp/info"
check "info: the scene's memory" grep -q '^scene memory .* instances 0.00' "$tmp/info"

# (the renders below in one batch: lib.sh, queue; the checks read them after it)
for m in normal depth albedo phong flat gouraud; do
    queue "i-$m" render "$I" -o "$tmp/i-$m.exr" --mode $m --size 48x48 --spp 1 $V
    queue "f-$m" render "$F" -o "$tmp/f-$m.exr" --mode $m --size 48x48 --spp 1 $V
done
queue s-phong render "$tmp/inst-short.gltf" -o "$tmp/s-phong.exr" --mode phong --size 48x48 --spp 1 $V
P="--size 40x40 --spp 128 --env 0,0,0 $V"
queue pi render "$I" -o "$tmp/pi.exr" $P --seed 1
queue pf render "$F" -o "$tmp/pf.exr" $P --seed 2
queue pf3 render "$F" -o "$tmp/pf3.exr" $P --seed 3
queue one render "$I" -o "$tmp/one.exr" --spp 3 --size 24x24 --env 0.3 --aov albedo,normal,depth $V
queue two GONIO_LOOP_CAP=3000 GONIO_DEBUG_RESUMES=1 render "$I" -o "$tmp/two.exr" --spp 3 --size 24x24 \
    --env 0.3 --aov albedo,normal,depth $V
queue frames render "$tmp/inst-anim.gltf" --camera 0 --size 32x32 --spp 1 --mode phong --fps 1 \
    --frames 0-2 -o "$tmp/fr_%d.exr"
for k in 0 2; do
    queue "frame-$k" render "$tmp/inst-anim.gltf" --camera 0 --size 32x32 --spp 1 --mode phong --fps 1 --frame $k \
        -o "$tmp/one_$k.exr" --quiet
done
S=$A/SimpleInstancing/glTF/SimpleInstancing.gltf
if [ -f "$S" ]; then
    python3 "$(dirname "$0")/../tool/instances.py" flatten "$S" "$tmp/si-flat.gltf"
    queue si render "$S" -o "$tmp/si.exr" --mode phong --size 64x64 --spp 1 --quiet
    queue si-flat render "$tmp/si-flat.gltf" -o "$tmp/si-flat.exr" --mode phong --size 64x64 --spp 1 --quiet
    queue si-png render "$S" -o "$tmp/si.png" --size 32x32 --spp 1
fi
while read -r bad path; do
    queue "bad-$bad" render "$tmp/bad-$bad.gltf" -o "$tmp/bad.exr" --quiet
done <"$tmp/bad.txt"
run_queue

# The local modes: the same pixels up to the transforms' rounding
for m in normal depth albedo phong flat gouraud; do
    if ! queued_ok "i-$m" "f-$m"; then fail "--mode $m renders"; continue; fi
    check "--mode $m: instances = flattened" "$G" diff "$tmp/i-$m.exr" "$tmp/f-$m.exr" --max-rmse 1e-3 --quiet
done
# ROTATION as normalized shorts: the quantized quaternions are a little off the floats
check_queued "ROTATION as normalized shorts renders" 0 s-phong
check "ROTATION as normalized shorts = floats" "$G" diff "$tmp/s-phong.exr" "$tmp/f-phong.exr" --max-rmse 3e-3 --quiet

# The path tracer, lit only by the instanced emitters (their world areas differ from the
# mesh's): instances against the flattened scene, on other seeds than a second flattened
# render, so that the two differences are both noise and must be alike
queued_ok pi pf pf3 || fail "path renders"
rmse() { "$G" diff "$1" "$2" | awk '$1 == "rmse" {print $2}'; }
bias() { "$G" diff "$1" "$2" | awk '$1 == "rel_bias" {print $2}'; }
a=$(rmse "$tmp/pi.exr" "$tmp/pf.exr") b=$(rmse "$tmp/pf3.exr" "$tmp/pf.exr") rb=$(bias "$tmp/pi.exr" "$tmp/pf.exr")
check "path: instances differ from flattened as two seeds do (rmse $a vs $b)" \
    python3 -c "import sys; sys.exit(0 if $a <= 1.2 * $b else 1)"
check "path: no bias (rel_bias $rb)" python3 -c "import sys; sys.exit(0 if abs($rb) <= 0.02 else 1)"

# The loop cap: paths interrupted in their walks, inside instances too, resume bit for bit
if queued_ok one two; then
    check "interrupted paths = whole paths" "$TESTTOOL" same "$tmp/one.exr" "$tmp/two.exr"
    n=$(sed -n 's/^gonio: debug: \([0-9]*\) dispatch.*/\1/p' "$tmp/queue/two.log")
    check "... and some were interrupted (${n:-no} resuming dispatches)" test "${n:-0}" -gt 0
else
    fail "interrupted paths (render failed)"; sed 's/^/    /' "$tmp/queue/one.log" "$tmp/queue/two.log"
fi

# An animation (--frames): a frame that only moves instances keeps the trees and kernels of the
# frame before and rebuilds only the top tree (a mesh used once that the animation moves is
# an instance for --frames); each frame is the one --frame renders alone
check_queued "--frames renders" 0 frames
check "... frames 1 and 2 rebuild only the top tree" \
    test "$(grep -c 'frame [12]: the same geometry, moved: the top tree over 20 instances rebuilt' "$tmp/queue/frames.log")" = 2
for k in 0 2; do
    check "... frame $k = --frame $k" "$G" diff "$tmp/fr_$k.exr" "$tmp/one_$k.exr" --max-rmse 1e-3 --quiet
done
check "... and the frames differ" sh -c "! '$G' diff '$tmp/fr_0.exr' '$tmp/fr_2.exr' --max-rmse 1e-2 --quiet"

# A Khronos sample: 125 instances of a cube, like its flattened self (S: the batch above)
if [ -f "$S" ]; then
    check "SimpleInstancing: 125 instances" sh -c "'$G' info '$S' | grep -q '^instances *125 '"
    check "SimpleInstancing = flattened" "$G" diff "$tmp/si.exr" "$tmp/si-flat.exr" --max-rmse 1e-3 --quiet
    check_queued "SimpleInstancing: no warning" 0 si-png
    check "... about the extension" sh -c "! grep -q 'warning' '$tmp/last'"
fi

# A wrong attribute: an error naming the file and the JSON path, no output
while read -r bad path; do
    check_queued "bad $bad: an error" 1 "bad-$bad"
    check "bad $bad: names $path" grep -qF "bad-$bad.gltf: $path" "$tmp/last"
done <"$tmp/bad.txt"
check "no output from bad files" test ! -e "$tmp/bad.exr"
finish
