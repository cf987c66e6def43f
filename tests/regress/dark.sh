#!/usr/bin/env bash
# dark.sh: the dark-view rule (docs/path-tracing.md, "Light when the scene has none") and the
# framing view's fit. A file whose own light leaves its view dark gets the studio added with
# a one-line message; a file whose light is deliberate (the Cornell box, a point light over a
# floor written here) renders bit for bit as with --env 0; --env 0 keeps a dark file dark.
# The framing view fills the frame with a tiny and a huge model (the red cube's box in the
# render, measured by testtool). Scenes are glTF JSON written here by Python.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
# Q ID ARGS...: queues a render (lib.sh: queue); the script's renders run in one batch,
# then the checks read each one's status, output ($tmp/last) and image.
Q() { local id=$1; shift; queue "$id" render --spp 4 --compression none "$@"; }
ADDED="added gonio's studio environment (--env 0 for the file's light alone)"
# The lit fraction of a render, as the rule defines it, computed here from the EXR by an
# independent reader: of the pixels with A > 0.5, the share with luminance above 0.02.
lit() {
    python3 -c "
import sys; sys.path.insert(0, '$(dirname "$0")/../tool'); import exrtool
a, ch = exrtool.read('$1')
R, G, B, A = (ch[c][1] for c in 'RGBA')
L = [0.2126 * r + 0.7152 * g + 0.0722 * b for r, g, b, al in zip(R, G, B, A) if al > 0.5]
print('%.3f' % (sum(x > 0.02 for x in L) / max(1, len(L))))"
}
env_of() { grep -a -o 'studio\|none' <<<"$(exrheader "$1" 2>/dev/null | grep 'gonio:environment')" | head -n 1; }

# ---- sample models whose own light leaves their view dark (slow: the fast tier's dim point
# light below is the same case on a scene written here) -----------------------------------
if in_tier slow; then
    A=${GONIO_ASSETS:-}
    if [ -n "$A" ] && [ -d "$A/gltf/IridescenceSuzanne" ] && [ -d "$A/gltf/LightsPunctualLamp" ]; then
        for m in IridescenceSuzanne LightsPunctualLamp; do
            Q "$m" "$A/gltf/$m/glTF/$m.gltf" -o "$tmp/$m.exr" --size 64x32
            Q "$m-0" "$A/gltf/$m/glTF/$m.gltf" -o "$tmp/$m-0.exr" --size 64x32 --env 0
        done
        run_queue
        for m in IridescenceSuzanne LightsPunctualLamp; do
            check_queued "$m renders" 0 "$m"
            cp "$tmp/last" "$tmp/msg"
            check "$m: the studio added, saying so" grep -qF "$ADDED" "$tmp/msg"
            check "$m: the header says studio" test "$(env_of "$tmp/$m.exr")" = studio
            check_queued "$m, --env 0" 0 "$m-0"
            got=$(lit "$tmp/$m-0.exr")
            check "$m: its own light leaves it dark (lit fraction $got < 0.6)" python3 -c "assert $got < 0.6"
        done
    else
        echo "  note: no IridescenceSuzanne / LightsPunctualLamp in GONIO_ASSETS: those checks skipped"
    fi
fi
in_tier fast || { finish; exit; }

# A white floor and a grey cube under a point light above the front: deliberate light that
# lights the view (no camera: the framing view).
python3 - "$tmp" <<'PY'
import sys
import gltf_fixture as gf
out = sys.argv[1]
def write(name, size, centre, with_floor, light, color):
    P, N, I = gf.box([c - size for c in centre], [c + size for c in centre])
    if with_floor:
        b = len(P) // 3; f = 4 * size; y = centre[1] - size
        P += [centre[0] - f, y, centre[2] - f, centre[0] + f, y, centre[2] - f, centre[0] + f, y, centre[2] + f, centre[0] - f, y, centre[2] + f]
        N += [0, 1, 0] * 4; I += [b, b + 2, b + 1, b, b + 3, b + 2]
    g = gf.Gltf()
    m = g.material({"pbrMetallicRoughness": {"baseColorFactor": color + [1], "metallicFactor": 0, "roughnessFactor": 1}})
    nodes = [g.node(mesh=g.mesh(g.primitive(P, N, I, m)))]
    if light:
        nodes.append(g.node(light=g.light("point", intensity=light),
                            translation=[centre[0] + 1.5 * size, centre[1] + 4 * size, centre[2] + 3 * size]))
    g.scene(nodes)
    g.write(f"{out}/{name}.gltf")
write("lit", 1.0, [0, 0, 0], True, 60.0, [0.8, 0.8, 0.8])
write("dim", 1.0, [0, 0, 0], True, 0.05, [0.8, 0.8, 0.8])
write("tiny", 1e-3, [5e-3, -2e-3, 1e-3], False, 0, [1, 0, 0])
write("huge", 1e4, [3e4, 1e4, -2e4], False, 0, [1, 0, 0])
PY

# ---- a camera inside a closed model: the headlight ----------------------------------------
# Three white boxes on a grey ground inside a closed, double-sided sky box, the camera among
# them, no light: the studio cannot reach the boxes. "open" is the same without the sky;
# "black" is black boxes on a black ground in the open (a dark view, but the studio reaches
# it: a black metal reflects nothing); "lamp" has a point light inside the sky that lights the view (deliberate: unchanged),
# "dimlamp" one 400 times dimmer (dark: the studio added, kept out, then the headlight).
python3 - "$tmp" <<'PY'
import sys
import gltf_fixture as gf
out = sys.argv[1]
def write(name, sky, lamp, dark=False):
    parts = [(gf.box([-20, -1, -20], [20, 0, 20]), 0)]
    parts += [(gf.box([x - 0.5, 0, z - 0.5], [x + 0.5, h, z + 0.5]), 1) for x, z, h in ((-1.5, -2, 1), (0.5, -4, 2), (2, -1.5, 0.8))]
    if sky:
        parts.append((gf.box([-25, -5, -25], [25, 25, 25]), 2))
    g = gf.Gltf()
    prims = [g.primitive(P, N, I, mat) for (P, N, I), mat in parts]
    colours = ([0.0] * 3, [0.0] * 3) if dark else ([0.5, 0.5, 0.5], [0.9, 0.9, 0.9])
    mats = [{"pbrMetallicRoughness": {"baseColorFactor": c + [1], "metallicFactor": 1 if dark else 0, "roughnessFactor": 1}} for c in colours + ([0.4, 0.6, 0.9],)]
    mats[2]["doubleSided"] = True
    for m in mats:
        g.material(m)
    nodes = [g.node(mesh=g.mesh(*prims)),
             g.node(camera=g.perspective(0.9, 0.05), translation=[0, 1.5, 4], rotation=[-0.13, 0, 0, 0.9915])]
    if lamp:
        nodes.append(g.node(light=g.light("point", intensity=lamp), translation=[1, 6, 3]))
    g.scene(nodes)
    g.write(f"{out}/{name}.gltf")
write("sky", True, 0)
write("open", False, 0)
write("black", False, 0, dark=True)
write("lamp", True, 400)
write("dimlamp", True, 1)
PY

# ---- the renders, queued ------------------------------------------------------------------
Q cornell scenes/cornell.gltf -o "$tmp/cornell.exr" --size 48x48
Q cornell-0 scenes/cornell.gltf -o "$tmp/cornell-0.exr" --size 48x48 --env 0
Q lit "$tmp/lit.gltf" -o "$tmp/lit.exr" --size 48x48
Q lit-0 "$tmp/lit.gltf" -o "$tmp/lit-0.exr" --size 48x48 --env 0
Q dim "$tmp/dim.gltf" -o "$tmp/dim.exr" --size 48x48
Q dim-0 "$tmp/dim.gltf" -o "$tmp/dim-0.exr" --size 48x48 --env 0
Q dim-s "$tmp/dim.gltf" -o "$tmp/dim-s.exr" --size 48x48 --env studio
Q dim-strict "$tmp/dim.gltf" -o "$tmp/dim-strict.exr" --size 48x48 --strict --quiet
for m in sky open black dimlamp lamp; do Q "$m" "$tmp/$m.gltf" -o "$tmp/$m.exr" --size 48x32; done
Q sky-s "$tmp/sky.gltf" -o "$tmp/sky-s.exr" --size 48x32 --env studio
Q sky-frames "$tmp/sky.gltf" --frames 0-1 -o "$tmp/sky-f%d.exr" --size 48x32
Q lamp-0 "$tmp/lamp.gltf" -o "$tmp/lamp-0.exr" --size 48x32 --env 0
for m in tiny huge; do Q "$m" "$tmp/$m.gltf" -o "$tmp/$m.exr" --size 64x64 --env 1; done
run_queue

# ---- deliberate light: unchanged --------------------------------------------------------
check_queued "Cornell box renders" 0 "cornell"
grep -q "$ADDED" "$tmp/last" && fail "Cornell box: the studio was added" || pass
check_queued "Cornell box with --env 0" 0 "cornell-0"
check "Cornell box: the same pixels as --env 0, bit for bit" "$TESTTOOL" same "$tmp/cornell.exr" "$tmp/cornell-0.exr"

check_queued "a point light over a floor renders" 0 "lit"
grep -q "$ADDED" "$tmp/last" && fail "a deliberate point light: the studio was added" || pass
got=$(lit "$tmp/lit.exr")
check "the point light lights the view itself (lit fraction $got >= 0.6)" python3 -c "assert $got >= 0.6"
check_queued "the point light with --env 0" 0 "lit-0"
check "a deliberate point light: the same pixels as --env 0, bit for bit" "$TESTTOOL" same "$tmp/lit.exr" "$tmp/lit-0.exr"

# ---- a dark view: the studio added, with the message; --env 0 keeps it dark ---------------
check_queued "a dim point light renders" 0 "dim"
cp "$tmp/last" "$tmp/msg"
check "a dim point light: the studio added, saying so" grep -qF "$ADDED" "$tmp/msg"
check "the message is one line" test "$(grep -c "studio" "$tmp/msg")" = 1
check "the header says studio" test "$(env_of "$tmp/dim.exr")" = studio
got=$(lit "$tmp/dim.exr")
check "with the studio the view is lit (lit fraction $got >= 0.6)" python3 -c "assert $got >= 0.6"
check_queued "a dim point light, --env 0" 0 "dim-0"
grep -q "studio" "$tmp/last" && fail "--env 0: the studio was added" || pass
got=$(lit "$tmp/dim-0.exr")
check "--env 0 keeps the dark file dark (lit fraction $got < 0.6)" python3 -c "assert $got < 0.6"
check_queued "--env studio given: no message of the rule" 0 "dim-s"
grep -q "$ADDED" "$tmp/last" && fail "an explicit --env studio printed the rule's message" || pass
check_queued "--strict (and --quiet): the studio added to a dark view is an error" 1 "dim-strict"
check "... said as one" grep -qF "gonio: error: $tmp/dim.gltf: its own light leaves the view dark" "$tmp/last"
check "... and nothing written" test ! -e "$tmp/dim-strict.exr"


HEAD="a headlight, a point light at the camera, replaces the studio"
check_queued "--frames with the headlight" 0 "sky-frames"
check "... keeps the renderer from frame to frame (the light is the rule's, not the geometry)" \
    grep -qF "frame 1: the same geometry, moved" "$tmp/last"
check "... and each frame is the render of the frame alone, bit for bit" "$TESTTOOL" same "$tmp/sky-f1.exr" "$tmp/sky.exr"
check_queued "a camera inside a closed sky, no light: renders" 0 "sky"
cp "$tmp/last" "$tmp/msg"
check "... a headlight added, saying why" grep -qF "the camera is inside a closed model (100 % of the rays from it meet the scene)" "$tmp/msg"
check "... in one line" test "$(grep -c "$HEAD" "$tmp/msg")" = 1
check "... and the header says so" test "$(exrheader "$tmp/sky.exr" 2>/dev/null | grep -a -c 'gonio:environment.*headlight')" = 1
got=$(lit "$tmp/sky.exr")
check "... and the view is lit (lit fraction $got >= 0.6)" python3 -c "assert $got >= 0.6"
check_queued "the studio alone (--env studio: no rule)" 0 "sky-s"
got=$(lit "$tmp/sky-s.exr")
check "... leaves the boxes in the closed sky dark (lit fraction $got < 0.6)" python3 -c "assert $got < 0.6"
check_queued "the same boxes with no sky render" 0 "open"
grep -qF "$HEAD" "$tmp/last" && fail "no sky: a headlight was added" || pass
check_queued "black boxes in the open render" 0 "black"
grep -qF "$HEAD" "$tmp/last" && fail "a dark model in the open: a headlight was added" || pass
got=$(lit "$tmp/black.exr")
check "... though the view is dark (lit fraction $got < 0.6): the camera is not enclosed" python3 -c "assert $got < 0.6"
check_queued "a dim lamp inside the closed sky renders" 0 "dimlamp"
cp "$tmp/last" "$tmp/msg"
check "... the studio added, then the headlight" sh -c "grep -qF \"$ADDED\" '$tmp/msg' && grep -qF '$HEAD' '$tmp/msg'"
got=$(lit "$tmp/dimlamp.exr")
check "... and the view is lit (lit fraction $got >= 0.6)" python3 -c "assert $got >= 0.6"
check_queued "a lamp inside the closed sky renders" 0 "lamp"
grep -q "$HEAD\|$ADDED" "$tmp/last" && fail "a lamp that lights the closed sky: light was added" || pass
check_queued "the lamp in the closed sky with --env 0" 0 "lamp-0"
check "... the same pixels, bit for bit" "$TESTTOOL" same "$tmp/lamp.exr" "$tmp/lamp-0.exr"

# ---- the framing view fills the frame ----------------------------------------------------
# A red cube under a constant environment: its projected box (testtool's red box) spans at
# least 85 % of the frame along its limiting axis, whatever its size and position.
for m in tiny huge; do
    check_queued "$m cube renders" 0 "$m"
    box=$("$TESTTOOL" stats "$tmp/$m.exr" | awk '{print $8, $9, $10, $11}')
    check "$m cube fills the frame (red box $box in 64x64)" sh -c \
        "echo $box | awk '{w = \$3 - \$1 + 1; h = \$4 - \$2 + 1; exit !(\$1 >= 0 && (w >= 0.85 * 64 || h >= 0.85 * 64) && w <= 64 && h <= 64)}'"
    check "$m cube: no pixel of it at the image's edge" sh -c \
        "echo $box | awk '{exit !(\$1 > 0 && \$2 > 0 && \$3 < 63 && \$4 < 63)}'"
done
finish
