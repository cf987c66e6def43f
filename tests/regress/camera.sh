#!/usr/bin/env bash
# camera.sh: which camera a render uses (the file's first camera in node order, --camera N,
# frame, --look-at, a view recorded in an EXR), orthographic cameras, --scene, and the
# header that records the camera. The scene is glTF JSON written here by Python, not by
# gonio: a white quad, a red square at a known point, three cameras in a node hierarchy.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scene"
S=$tmp/cameras.gltf
python3 - "$S" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf(generator="camera.sh")
white = g.material({"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0}})
red = g.material({"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1], "metallicFactor": 0}})
quad = g.mesh(g.quad(white, half=5, uv=False))
square = g.mesh(g.quad(red, half=0.5, uv=False))  # the red square, around its node
B = g.perspective(0.5, 0.1, aspect=1, name="B")
A = g.perspective(0.5, 0.1, aspect=1, name="A")
C = g.orthographic(2, 1, name="C")
# Depth-first: node 0 (quad), its child 3 (camera A), node 1 (camera B), node 2 (red square
# at (1.3, 0.4)), its child 4 (camera C, 5 above the square).
g.node(mesh=quad, children=[3])
g.node(camera=B, translation=[0, 0, 5])
g.node(mesh=square, translation=[1.3, 0.4, 0.01], children=[4])
g.node(camera=A, translation=[1.3, 0.4, 5])
g.node(camera=C, translation=[0, 0, 5])
g.scene([0, 1, 2])
g.scene([1, 2])
g.write(sys.argv[1])
PY
[ -s "$S" ] || skip_all "could not write the test scene"

stats() { "$TESTTOOL" stats "$1"; }
centre_is() { # centre_is FILE.exr red|white: the centre pixel's colour (odd sizes)
    local want=$1 f=$2 box
    box=$(stats "$f" | awk '{print $8, $9, $10, $11}')
    read -r x0 y0 x1 y1 <<<"$box"
    local c=16 inside=0
    [ "$x0" -ge 0 ] && [ "$x0" -le $c ] && [ "$x1" -ge $c ] && [ "$y0" -le $c ] && [ "$y1" -ge $c ] && inside=1
    if [ "$want" = red ]; then [ $inside = 1 ]; else [ $inside = 0 ]; fi
}
# R ARGS...: renders the scene's albedo; Q ID ARGS...: queues the same render (lib.sh: queue).
# The renders run in one batch, then the checks read each one's status, output ($tmp/last)
# and image. Usage errors (exit 2) stay processes of their own (cheap: no device).
albedo=(render "$S" --mode albedo --spp 1 --quiet)
R() { "$G" "${albedo[@]}" "$@"; }
Q() { local id=$1; shift; queue "$id" "${albedo[@]}" "$@"; }

# ---- the renders, queued (in order: --camera FILE.exr reads an earlier line's EXR) -------
Q default -o "$tmp/default.exr" --size 33x33
queue d2 render "$S" --mode albedo --spp 1 --size 33x33 -o "$tmp/d2.exr"
Q b -o "$tmp/b.exr" --size 33x33 --camera 1
Q a -o "$tmp/a.exr" --size 33x33 --camera 0
Q cam3 -o "$tmp/x.exr" --size 33x33 --camera 3
Q a65 -o "$tmp/a65.exr" --size 65x65
Q ortho -o "$tmp/ortho.exr" --size 64x32 --camera 2
Q ortho-size -o "$tmp/ortho-size.exr" --camera 2
Q frame -o "$tmp/frame.exr" --size 33x33 --camera frame
Q look -o "$tmp/look.exr" --size 33x33 --look-at 1.3,0.4,3,1.3,0.4,0 --fov 20
Q look2 -o "$tmp/look2.exr" --size 33x33 --look-at 0,0,3,0,0,0,0,1,0
Q again -o "$tmp/again.exr" --size 33x33 --camera "$tmp/look.exr"
Q again-a -o "$tmp/again-a.exr" --size 65x65 --camera "$tmp/a65.exr"
Q again-o -o "$tmp/again-o.exr" --camera "$tmp/ortho.exr"
Q scene1 -o "$tmp/scene1.exr" --size 33x33 --scene 1
queue s1 render "$S" --mode albedo --spp 1 --size 33x33 --scene 1 -o "$tmp/s1.exr"
Q scene2 -o "$tmp/x.exr" --scene 2
queue cmp compare "$S" -o "$tmp/cmp" --spp 1 --size 33x33 --quiet
run_queue

# ---- the default: the first camera of the default scene in depth-first node order (A) ----
check_queued "default camera renders" 0 default
check "default camera is A (looks at the red square)" centre_is red "$tmp/default.exr"
check "summary line names the camera" grep -q "camera 0 'A'" "$tmp/queue/d2.log"
check_queued "--camera 1 is B" 0 b
check "B looks at the white quad" centre_is white "$tmp/b.exr"
check_queued "--camera=0 is A" 0 a
check "A and the default agree" "$G" diff "$tmp/a.exr" "$tmp/default.exr" --max-error 0 --quiet
check_queued "--camera 3 does not exist" 1 cam3
check "error names the scene and the count" grep -q "cameras.gltf: --camera 3: the scene has 3 camera" "$tmp/last"
check_fails "--camera bogus is a usage error" 2 R -o "$tmp/x.exr" --camera bogus

# Perspective geometry: A's red box from the pinhole model, computed here.
check_queued "A at 65x65" 0 a65
want=$(python3 -c '
import math
H = 65; th = math.tan(0.25); d = 5 - 0.01
rows = [y for y in range(H) if abs((1 - 2 * (y + 0.5) / H) * th * d) <= 0.5]
print(rows[0], rows[0], rows[-1], rows[-1])')
got=$(stats "$tmp/a65.exr" | awk '{print $8, $9, $10, $11}')
check "perspective: the red square spans the pixels the pinhole model says ($want)" test "$got" = "$want"

# ---- orthographic: xmag 2, ymag 1 -> the 1 x 1 square is a quarter of the width and half
# of the height, whatever the distance --------------------------------------------------
check_queued "--camera 2 (orthographic) renders" 0 ortho
got=$(stats "$tmp/ortho.exr" | awk '{print $8, $9, $10, $11}')
check "orthographic: the square covers columns 24-39 and rows 8-23 (got $got)" test "$got" = "24 8 39 23"
check_queued "orthographic default size follows xmag/ymag" 0 ortho-size
check "512x256" sh -c "exrheader '$tmp/ortho-size.exr' | grep -q 'dataWindow.*(0 0) - (511 255)'"

# ---- framing, look-at, --fov ----------------------------------------------------------------
check_queued "--camera frame renders" 0 frame
check "the framing view sees both the quad and the square" sh -c \
    "'$TESTTOOL' stats '$tmp/frame.exr' | awk '{exit !(\$2 > 200 && \$8 >= 0)}'"
check_queued "--look-at at the square" 0 look
check "look-at centre is red" centre_is red "$tmp/look.exr"
check_queued "--look-at=... at the origin" 0 look2
check "look-at origin centre is white" centre_is white "$tmp/look2.exr"
# --fov 20 at distance 3: tan(10 deg) * 3 = 0.529 half-height, so the 0.5 square nearly fills it.
got=$(stats "$tmp/look.exr" | awk '{print $9, $11}')
check "--fov: the square fills rows 1-31 of 33 (got $got)" test "$got" = "1 31"
check_fails "--look-at with the target at the eye" 2 R -o "$tmp/x.exr" --look-at 1,1,1,1,1,1
check_fails "--look-at with 5 numbers" 2 R -o "$tmp/x.exr" --look-at 1,1,1,1,1
check_fails "--fov 0" 2 R -o "$tmp/x.exr" --fov 0

# ---- the header records the camera, and --camera FILE.exr reproduces it ------------------
exrheader "$tmp/look2.exr" >"$tmp/hdr.txt" 2>&1
check "header: gonio:camera-name" grep -q 'gonio:camera-name (type string): "look-at' "$tmp/hdr.txt"
check "header: worldToCamera is an m44f" grep -q 'worldToCamera (type m44f)' "$tmp/hdr.txt"
# Eye (0,0,3) looking down -Z: right +X, up +Y, view +Z in camera space = -Z in the world,
# so p' = p M with rows (1 0 0 0) (0 1 0 0) (0 0 -1 0) (0 0 3 1).
m44=$(awk '/worldToCamera/ {f = 1; next} f && n < 4 {gsub(/[()]/, ""); print; n++}' "$tmp/hdr.txt" | tr -s ' \n' ' ')
check "worldToCamera of an eye at (0,0,3) looking down -Z ($m44)" python3 -c '
import sys
got = [float(v) for v in sys.argv[1].split()]
want = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 3, 1]
sys.exit(not (len(got) == 16 and all(abs(a - b) < 1e-6 for a, b in zip(got, want))))' "$m44"
check_queued "--camera FILE.exr takes the recorded view" 0 again
check "... and gives the same pixels" "$G" diff "$tmp/again.exr" "$tmp/look.exr" --max-error 0 --quiet
check_queued "--camera FILE.exr of a file camera" 0 again-a
check "... the same pixels as that camera" "$G" diff "$tmp/again-a.exr" "$tmp/a65.exr" --max-error 0 --quiet
# Without --size, the file's own size (a 64x32 orthographic render), and the same identity,
# so the two renders are one image to gonio merge.
check_queued "--camera FILE.exr without --size" 0 again-o
check "... renders the file's 64x32" sh -c "exrheader '$tmp/again-o.exr' | grep -q 'dataWindow.*(0 0) - (63 31)'"
check "... the same pixels" "$G" diff "$tmp/again-o.exr" "$tmp/ortho.exr" --max-error 0 --quiet
cam_id() { exrheader "$1" | grep 'gonio:camera (type string)'; }
check "... and the same gonio:camera identity" test "$(cam_id "$tmp/again-o.exr")" = "$(cam_id "$tmp/ortho.exr")"
check "an EXR without a view" "$TESTTOOL" ref plane depth 8 8 "$tmp/noview.exr"
check_fails "--camera of an EXR without a view" 2 R -o "$tmp/x.exr" --camera "$tmp/noview.exr"
check "... says so" grep -q "not an EXR with a gonio:look-at header" "$tmp/last"
check_fails "--camera of a missing EXR" 2 R -o "$tmp/x.exr" --camera "$tmp/nonexistent.exr"

# ---- --scene ---------------------------------------------------------------------------
check_queued "--scene 1 renders" 0 scene1
check "scene 1's first camera is B" grep -q "camera 0 'B'" "$tmp/queue/s1.log"
check "scene 1 has no quad: the centre is background" sh -c \
    "'$TESTTOOL' stats '$tmp/scene1.exr' | awk '{exit !(\$2 < 33 * 33)}'"
check_queued "--scene 2 does not exist" 1 scene2
check "error names the scene count" grep -q "the file has 2 scene" "$tmp/last"

# ---- the other commands follow the same rule ------------------------------------------------
check_queued "compare uses the default camera" 0 cmp
finish
