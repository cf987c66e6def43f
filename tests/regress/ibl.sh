#!/usr/bin/env bash
# ibl.sh: EXT_lights_image_based, the file's image-based light, against answers computed here
# from the extension's definition: cube faces of one colour each, seen by cameras at the
# centre looking along each axis, give each face's radiance (LDR faces through sRGB, RGBD
# faces as RGB^2.2 / D, times the light's intensity); a face split left red / right blue shows
# red on the left (the faces are pictures seen from the centre); the light's rotation turns
# the cube (q = 90 degrees about +Y puts the +X face ahead of a camera looking along -Z);
# --env replaces the file's light; bad lights are errors naming their JSON path.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
root=$(cd "$(dirname "$0")/../.." && pwd)

write_scenes <<'PY'
import math, sys
import gltf_fixture as gf
out = sys.argv[1]

S = 16
# (colour, alpha or None): faces +X, -X, +Y, -Y, +Z, -Z; +Y and -Z are RGBD
faces = [((200, 40, 40), None), ((40, 200, 40), None), ((180, 120, 60), 64),
         ((40, 40, 200), None), ((200, 200, 40), None), ((90, 160, 220), 32)]
def srgb(v):
    v /= 255
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4
def radiance(f, intensity):
    c, a = faces[f]
    return [(((v / 255) ** 2.2) / (a / 255) if a else srgb(v)) * intensity for v in c]

s2 = math.sqrt(0.5)
looks = {"+X": [0, -s2, 0, s2], "-X": [0, s2, 0, s2], "+Y": [s2, 0, 0, s2], "-Y": [-s2, 0, 0, s2],
         "+Z": [0, 1, 0, 0], "-Z": [0, 0, 0, 1]}
def scene(name, images, light=None, rotation=None, intensity=None, yfov=0.2, extra=None):
    g = gf.Gltf()
    l = {"irradianceCoefficients": [[0, 0, 0]] * 9, "specularImageSize": S,
         "specularImages": [list(range(6))]}
    if rotation: l["rotation"] = rotation
    if intensity is not None: l["intensity"] = intensity
    if light: l.update(light)
    g.extend(g.doc, "EXT_lights_image_based", lights=[l])
    # one small triangle far away along (1, 1, 1), in no camera's view; a camera per axis
    nodes = [g.node(mesh=g.mesh(g.primitive([10, 11, 10, 11, 10, 10, 10, 10, 11])))]
    cam = g.perspective(yfov, 0.01, aspect=1)
    nodes += [g.node(camera=cam, rotation=q, name=k) for k, q in looks.items()]
    g.scene(nodes, extensions={"EXT_lights_image_based": {"light": 0}})
    for i, data in enumerate(images):
        open(f"{out}/{name}-{i}.png", "wb").write(data)
        g.image(uri=f"{name}-{i}.png")
    if extra: extra(g.doc)
    g.write(f"{out}/{name}.gltf")

uniform = [gf.png(S, S, lambda x, y, c=c, a=a: c + ((a,) if a else ()), 3 if a is None else 4) for c, a in faces]
scene("faces", uniform)
scene("bright", uniform, intensity=2.5)
scene("turned", uniform, rotation=[0, s2, 0, s2])
# -Z split: left half red, right half blue (as seen from the centre)
split = list(uniform)
split[5] = gf.png(S, S, lambda x, y: (220, 30, 30) if x < S // 2 else (30, 30, 220), 3)
scene("split", split, yfov=1.0)
# bad lights
scene("bad-index", uniform, light={"specularImages": [[0, 1, 2, 3, 4, 9]]})
scene("bad-six", uniform, light={"specularImages": [[0, 1, 2, 3, 4]]})
scene("bad-irr", uniform, light={"irradianceCoefficients": [[0, 0, 0]] * 8})
scene("bad-size", uniform, light={"specularImageSize": 32})
scene("bad-rot", uniform, rotation=[0, 1, 0, 1])
scene("bad-scene", uniform, extra=lambda d: d["scenes"][0]["extensions"]["EXT_lights_image_based"].update(light=3))
scene("bad-image", uniform[:5] + [b"not a png"])
with open(f"{out}/expect.txt", "w") as e:
    for i, k in enumerate(looks):
        e.write("faces %d %s %s\n" % (i, k, " ".join("%.6g" % v for v in radiance(i, 1))))
        e.write("bright %d %s %s\n" % (i, k, " ".join("%.6g" % v for v in radiance(i, 2.5))))
    e.write("turned 5 -Z %s\n" % " ".join("%.6g" % v for v in radiance(0, 1)))
    e.write("split-left 5 -Z %s\n" % " ".join("%.6g" % v for v in [srgb(220), srgb(30), srgb(30)]))
    e.write("split-right 5 -Z %s\n" % " ".join("%.6g" % v for v in [srgb(30), srgb(30), srgb(220)]))
PY

# pixel IMAGE.exr X Y: its R G B
pixel() {
    python3 - "$root/tests/tool" "$@" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import exrtool
attrs, ch = exrtool.read(sys.argv[2])
w = next(int.from_bytes(v[8:12], "little") - int.from_bytes(v[0:4], "little") + 1 for n, t, v in attrs if n == "dataWindow")
x, y = int(sys.argv[3]), int(sys.argv[4])
print(" ".join("%.6g" % ch[c][1][y * w + x] for c in "RGB"))
PY
}
# near WANT GOT: every channel within 2% (8-bit faces resampled into the lat-long map)
near() {
    python3 -c 'import sys; w=[float(v) for v in sys.argv[1].split()]; g=[float(v) for v in sys.argv[2].split()]
sys.exit(0 if all(abs(a-b) <= 0.02*max(a, 0.01) for a, b in zip(w, g)) else 1)' "$1" "$2"
}
# The renders run in one batch (lib.sh: queue); the checks below read each line's status,
# output and image. (The bad lights below fail before any device: processes of their own.)
render() { # render ID SCENE CAMERA OUT [ARGS...]: queues the render
    local id=$1 s=$2 cam=$3 o=$4; shift 4
    queue "$id" render "$tmp/$s.gltf" --camera "$cam" --size 16x16 --spp 4 --compression none -o "$o" --quiet "$@"
}

while read -r what cam axis r g b; do
    case $what in
    faces | bright) render "$what-$cam" "$what" "$cam" "$tmp/$what-$cam.exr" ;;
    turned) render turned turned "$cam" "$tmp/turned.exr" ;;
    split-left) render split split "$cam" "$tmp/split.exr" --size 32x32 ;;
    esac
done < "$tmp/expect.txt"
queue msg render "$tmp/faces.gltf" --camera 5 --size 8x8 --spp 1 -o "$tmp/m.exr"
render env0 faces 5 "$tmp/env0.exr" --env 0
run_queue

while read -r what cam axis r g b; do
    case $what in
    faces | bright)
        o=$tmp/$what-$cam.exr
        if queued_ok "$what-$cam"; then
            got=$(pixel "$o" 8 8)
            near "$r $g $b" "$got" && pass || fail "$what: the camera looking along $axis sees $got, not the face's $r $g $b"
        else fail "$what: camera $cam renders"; fi ;;
    turned)
        o=$tmp/turned.exr
        queued_ok turned && got=$(pixel "$o" 8 8) && near "$r $g $b" "$got" && pass ||
            fail "turned by 90 degrees about +Y: along -Z the +X face ($r $g $b) is expected, got ${got:-nothing}" ;;
    split-left | split-right)
        o=$tmp/split.exr
        x=8; [ $what = split-right ] && x=24
        got=$(pixel "$o" $x 16)
        near "$r $g $b" "$got" && pass || fail "$what: pixel ($x, 16) is $got, not $r $g $b (the face is a picture seen from the centre)" ;;
    esac
done < "$tmp/expect.txt"

# the default: the file's light, announced; --env replaces it; gonio info names it
msg=$(cat "$tmp/queue/msg.log")
[[ $msg == *"image-based light"*"EXT_lights_image_based light 0"* ]] && pass || fail "the render says what lights it: $msg"
queued_ok env0 && [ "$(pixel "$tmp/env0.exr" 8 8)" = "0 0 0" ] && pass || fail "--env 0 replaces the file's light"
"$G" info "$tmp/faces.gltf" | grep -q "^environment *EXT_lights_image_based light 0, 6 faces of 16x16" && pass || fail "gonio info names the environment"

# bad lights: exit 1, the JSON path or the face named, no output
check_bad() { # check_bad SCENE EXPECTED_TEXT
    local m
    m=$("$G" render "$tmp/$1.gltf" --size 8x8 --spp 1 -o "$tmp/$1.exr" 2>&1)
    local rc=$?
    [ $rc = 1 ] && [[ $m == *"$2"* ]] && [ ! -e "$tmp/$1.exr" ] && pass || fail "$1: exit $rc, expected 1 and '$2': $m"
}
check_bad bad-index "extensions.EXT_lights_image_based.lights[0].specularImages[0][5]: 9 does not exist"
check_bad bad-six "specularImages[0]: [0,1,2,3,4] is not an array of 6 image indices"
check_bad bad-irr "lights[0].irradianceCoefficients: must have 9 entries (has 8)"
check_bad bad-size "is 16x16: the faces must be square, specularImageSize (32)"
check_bad bad-rot "lights[0].rotation: is not a unit quaternion"
check_bad bad-scene "scenes[0].extensions.EXT_lights_image_based.light: 3 does not exist"
check_bad bad-image "the -Z face, image 5"
finish
