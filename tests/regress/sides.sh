#!/usr/bin/env bash
# sides.sh: single-sided materials (glTF doubleSided false, the default). Camera rays do not
# see the back of a single-sided triangle; other rays see both sides (docs/path-tracing.md,
# "Single-sided materials"). A red quad turned away from the camera, in front of a green
# double-sided one, shows the green one (path and the local modes); double-sided, or turned
# toward the camera, it hides it. A large single-sided quad behind the camera, its back to the
# scene, still shades the green quad from the environment (the bounce rays see its back): the
# quad renders darker than without it.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"

# gen.py OUT.gltf QUAD...: QUAD = z,half-size,r,g,b,double(0|1),facing(+1|-1): a square at
# depth z facing +z or -z by its winding and normals (gltf_fixture's quad); an orthographic
# camera at z = 5 looks down -z.
cat >"$tmp/gen.py" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf()
for q in sys.argv[2:]:
    z, s, r, green, b, double, facing = map(float, q.split(","))
    m = g.material({"pbrMetallicRoughness": {"baseColorFactor": [r, green, b, 1], "metallicFactor": 0, "roughnessFactor": 1},
                    "doubleSided": double > 0})
    g.node(mesh=g.mesh(g.quad(m, half=s, z=z, facing=facing, uv=False)))
g.node(camera=g.orthographic(), translation=[0, 0, 5])
g.scene(range(len(g.doc["nodes"])))
g.write(sys.argv[1])
PY
# centre.py IMAGE.exr TOOLDIR: the mean R G B of the 4x4 pixels at the centre
cat >"$tmp/centre.py" <<'PY'
import sys
sys.path.insert(0, sys.argv[2])
import exrtool
hdr, ch = exrtool.read(sys.argv[1])
R, G, B = (ch[c][1] for c in "RGB")
w = 16; h = len(R) // w
px = [y * w + x for y in range(h // 2 - 2, h // 2 + 2) for x in range(w // 2 - 2, w // 2 + 2)]
print(" ".join("%.5f" % (sum(C[i] for i in px) / len(px)) for C in (R, G, B)))
PY
T=$(dirname "$0")/../tool
GREEN=-1,1,0.1,0.8,0.1,1,1
RED_AWAY=0,0.5,0.8,0.1,0.1,0,-1
RED_AWAY_DOUBLE=0,0.5,0.8,0.1,0.1,1,-1
RED_TOWARD=0,0.5,0.8,0.1,0.1,0,1
python3 "$tmp/gen.py" "$tmp/away.gltf" $GREEN $RED_AWAY &&
    python3 "$tmp/gen.py" "$tmp/double.gltf" $GREEN $RED_AWAY_DOUBLE &&
    python3 "$tmp/gen.py" "$tmp/toward.gltf" $GREEN $RED_TOWARD &&
    python3 "$tmp/gen.py" "$tmp/open.gltf" $GREEN &&
    python3 "$tmp/gen.py" "$tmp/roof.gltf" $GREEN 6,20,0.5,0.5,0.5,0,1 || fail "scenes"

# instances (a mesh two nodes use is kept once and placed twice: docs/architecture.md): the
# red quad's mesh used by a second node out of view, and the red quad's node as is (0),
# mirrored in z (1: a negative determinant, whose front glTF defines as the authored side,
# now toward +z) or turned 180 degrees about y (2): 1 and 2 turn the away quad toward the
# camera and the toward quad away
inst() { # inst IN OUT VARIANT
    python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
d["nodes"].insert(2, {"mesh": 1, "translation": [10, 0, 0]})
if sys.argv[3] == "1": d["nodes"][1]["scale"] = [1, 1, -1]
if sys.argv[3] == "2": d["nodes"][1]["rotation"] = [0, 1, 0, 0]
d["scenes"][0]["nodes"] = list(range(len(d["nodes"])))
json.dump(d, open(sys.argv[2], "w"))' "$1" "$2" "$3"
}
for m in 0 1 2; do
    inst "$tmp/away.gltf" "$tmp/away-inst$m.gltf" $m && inst "$tmp/toward.gltf" "$tmp/toward-inst$m.gltf" $m || fail "instanced scenes"
done

# The renders run in one batch (lib.sh: queue); the checks below read each line's status
# and image.
# queue_colour SCENE MODE: queues the render that colour reads
queue_colour() {
    queue "$1-$2" render "$tmp/$1.gltf" --mode $2 --spp 8 --size 16x16 --env 1 --compression none --quiet -o "$tmp/$1-$2.exr"
}
# colour SCENE MODE: "green" or "red", the colour at the centre (of the queued render)
colour() {
    queued_ok "$1-$2" || return 1
    python3 "$tmp/centre.py" "$tmp/$1-$2.exr" "$T" | awk '{print ($2 > 2 * $1 ? "green" : $1 > 2 * $2 ? "red" : "neither")}'
}
for mode in path albedo phong; do
    for sc in away double toward; do queue_colour $sc $mode; done
done
for m in 0 1 2; do queue_colour away-inst$m path; queue_colour toward-inst$m path; done
for sc in open roof; do
    queue "$sc" render "$tmp/$sc.gltf" --spp 64 --size 16x16 --env 1 --compression none --quiet -o "$tmp/$sc.exr"
done
run_queue

for mode in path albedo phong; do
    got=$(colour away $mode)
    [ "$got" = green ] && pass || fail "$mode: a single-sided quad turned away hides what is behind it ($got at the centre)"
    got=$(colour double $mode)
    [ "$got" = red ] && pass || fail "$mode: the same quad double-sided is not seen ($got at the centre)"
    got=$(colour toward $mode)
    [ "$got" = red ] && pass || fail "$mode: a single-sided quad turned toward the camera is not seen ($got at the centre)"
done
for m in 0 1 2; do
    "$G" info "$tmp/away-inst$m.gltf" | grep -q "^instances *[1-9]" && pass || fail "the instanced scene has instances"
    what=("an instance" "a mirrored instance" "a turned instance")
    want_away=green want_toward=red
    [ $m != 0 ] && want_away=red want_toward=green
    got=$(colour away-inst$m path)
    [ "$got" = $want_away ] && pass || fail "path: the away quad as ${what[$m]}: $got at the centre, not $want_away"
    got=$(colour toward-inst$m path)
    [ "$got" = $want_toward ] && pass || fail "path: the toward quad as ${what[$m]}: $got at the centre, not $want_toward"
done

# bounce rays see a back face: the roof behind the camera (its back to the scene) shades the
# green quad from the environment above it
lum() {
    queued_ok "$1" &&
        python3 "$tmp/centre.py" "$tmp/$1.exr" "$T" | awk '{print 0.2126 * $1 + 0.7152 * $2 + 0.0722 * $3}'
}
open=$(lum open) roof=$(lum roof)
if awk -v o="$open" -v r="$roof" 'BEGIN {exit !(o > 0.2 && r != "" && r > 0 && r < 0.6 * o)}'; then pass; else
    fail "the back of a single-sided roof does not shade the quad under it (open sky $open, roofed $roof)"
fi
finish
