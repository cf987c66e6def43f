#!/usr/bin/env bash
# skin.sh: skins and morph targets end to end. A scene written here, a morphed quad (two
# targets, one sparse, weights animated by a CUBICSPLINE sampler) and a two-bone skinned strip
# (its second joint's rotation animated, LINEAR; the skinned node's own transform, which glTF
# says to ignore, moves it 2 units away) side by side under an orthographic camera, is
# rendered at --at T in depth mode; the depth at pixel centres inside the triangles is
# compared with the posed positions Python computes here from the specification's formulas
# (its own quaternion slerp and matrices, the Hermite form, barycentric interpolation).
# Then the loader's checks: each broken variant of the scene is refused, naming the JSON
# path; `gonio info` counts skins, joints and morph targets; the sample models with skins
# and morph targets render at a time of their animations without a warning.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the scenes"
TOOL=$(cd "$(dirname "$0")/../tool" && pwd)

python3 - "$tmp" <<'PY'
import math, sys
import gltf_fixture as gf
out = sys.argv[1]
g = gf.Gltf()
U16 = gf.UNSIGNED_SHORT
# the morphed quad, left half: base z 0, target 0 lifts the corners by 0, 0.4, 1, 0.2,
# target 1 (sparse: no buffer view) lifts corner 3 by 0.8
quad = [(-0.9, -0.8, 0), (-0.1, -0.8, 0), (-0.1, 0.8, 0), (-0.9, 0.8, 0)]
qpos = g.accessor(sum(map(list, quad), []), "VEC3", bounds=True)
qidx = g.accessor([0, 1, 2, 0, 2, 3], "SCALAR", U16)
t0 = [0, 0, 0, 0, 0, 0.4, 0, 0, 1, 0, 0, 0.2]
qt0 = g.accessor(t0, "VEC3")
# target 1's sparse indices (padded to 4 bytes) and values: accessors too (the accessor
# numbers the broken variants' messages name below count them)
iv = g.doc["accessors"][g.accessor([3, 0], "SCALAR", U16, count=1)]["bufferView"]
vv = g.doc["accessors"][g.accessor([0, 0, 0.8], "VEC3")]["bufferView"]
qt1 = g.add("accessors", {"componentType": gf.FLOAT, "type": "VEC3", "count": 4,
                          "sparse": {"count": 1, "indices": {"bufferView": iv, "componentType": U16},
                                     "values": {"bufferView": vv}}})
# CUBICSPLINE weights, keys at 0 and 1: (in, value, out) per key, 2 targets each
wkeys = g.accessor([0, 1], "SCALAR", bounds=True)
wcub = [0, 0, 0.2, 0.1, 1.5, -0.5, -1, 0.5, 1, 0.6, 0, 0]
wout = g.accessor(wcub, "SCALAR")
# the skinned strip, right half: rows y -0.8, 0, 0.8; joint 0 at (0.5, -0.8, 0), joint 1 its
# child at (0, 0.8, 0); row 0 joint 0, row 1 half each, row 2 joint 1
strip = [(x, y, 0) for y in (-0.8, 0, 0.8) for x in (0.1, 0.9)]
spos = g.accessor(sum(map(list, strip), []), "VEC3", bounds=True)
sidx = g.accessor([0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4], "SCALAR", U16)
sj = g.accessor([0, 1, 0, 0] * 6, "VEC4", gf.UNSIGNED_BYTE)
sw = g.accessor([1, 0, 0, 0] * 2 + [0.5, 0.5, 0, 0] * 2 + [0, 1, 0, 0] * 2, "VEC4")
ibm = g.accessor([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.5, 0.8, 0, 1,
                  1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.5, 0, 0, 1], "MAT4")
rkeys = g.accessor([0, 1], "SCALAR", bounds=True)
s30 = math.sin(math.radians(30))
rout = g.accessor([0, 0, 0, 1, s30, 0, 0, math.cos(math.radians(30))], "VEC4")
morphed = g.mesh({"attributes": {"POSITION": qpos}, "indices": qidx, "targets": [{"POSITION": qt0}, {"POSITION": qt1}]},
                 weights=[0.5, 0.5])
skinned = g.mesh({"attributes": {"POSITION": spos, "JOINTS_0": sj, "WEIGHTS_0": sw}, "indices": sidx})
g.node(mesh=morphed)
g.node(mesh=skinned, skin=0, translation=[0, 0, -2])
g.node(translation=[0.5, -0.8, 0], children=[3])
g.node(translation=[0, 0.8, 0])
g.node(camera=g.orthographic(), translation=[0, 0, 5])
g.scene([0, 1, 2, 4])
g.add("skins", {"joints": [2, 3], "inverseBindMatrices": ibm})
g.add("animations", {"samplers": [{"input": wkeys, "output": wout, "interpolation": "CUBICSPLINE"},
                                  {"input": rkeys, "output": rout}],
                     "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}},
                                  {"sampler": 1, "target": {"node": 3, "path": "rotation"}}]})
g.write(out + "/pose.gltf")

# ---- the expected pose at T, computed here ----
def weights_at(t):
    if t < 0:
        return [0.5, 0.5]
    u = min(t, 1.0)
    h00, h10, h01, h11 = 2*u**3 - 3*u**2 + 1, u**3 - 2*u**2 + u, -2*u**3 + 3*u**2, u**3 - u**2
    key = lambda k, part, j: wcub[(k * 3 + part) * 2 + j]
    return [h00 * key(0, 1, j) + h10 * key(0, 2, j) + h01 * key(1, 1, j) + h11 * key(1, 0, j) for j in range(2)]
def slerp(a, b, u):
    dot = sum(x * y for x, y in zip(a, b))
    th = math.acos(max(-1.0, min(1.0, dot)))
    if th < 1e-9:
        return a
    return [(math.sin((1 - u) * th) * x + math.sin(u * th) * y) / math.sin(th) for x, y in zip(a, b)]
def quat_matrix(q):
    x, y, z, w = q
    return [[1 - 2*(y*y + z*z), 2*(x*y - z*w), 2*(x*z + y*w)],
            [2*(x*y + z*w), 1 - 2*(x*x + z*z), 2*(y*z - x*w)],
            [2*(x*z - y*w), 2*(y*z + x*w), 1 - 2*(x*x + y*y)]]
def posed(t):
    w = weights_at(t)
    q = [(x, y, z + w[0] * t0[3 * i + 2] + (w[1] * 0.8 if i == 3 else 0)) for i, (x, y, z) in enumerate(quad)]
    r = quat_matrix(slerp([0, 0, 0, 1], [s30, 0, 0, math.cos(math.radians(30))], min(max(t, 0), 1)))
    pivot = (0.5, 0.0, 0.0)  # joint 1's world origin; J1 p = pivot + R (p - pivot), J0 = identity
    s = []
    for i, p in enumerate(strip):
        d = [p[k] - pivot[k] for k in range(3)]
        j1 = [pivot[k] + sum(r[k][m] * d[m] for m in range(3)) for k in range(3)]
        a = [1, 1, 0.5, 0.5, 0, 0][i]
        s.append(tuple(a * p[k] + (1 - a) * j1[k] for k in range(3)))
    return [(q, [(0, 1, 2), (0, 2, 3)]), (s, [(0, 1, 3), (0, 3, 2), (2, 3, 5), (2, 5, 4)])]
N = 128
for t in (-1, 0.4, 0.75):
    lines = []
    for verts, tris in posed(t):
        for tri in tris:
            a, b, c = (verts[k] for k in tri)
            det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
            for py in range(N):
                for px in range(N):
                    x, y = -1 + (px + 0.5) * 2 / N, 1 - (py + 0.5) * 2 / N
                    l1 = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det
                    l2 = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det
                    l0 = 1 - l1 - l2
                    if min(l0, l1, l2) > 0.03 and (px + py) % 7 == 0:
                        z = l0 * a[2] + l1 * b[2] + l2 * c[2]
                        # the samples spread over the pixel: a quarter pixel of the depth's slope
                        gx = (b[2] - a[2]) * (c[1] - a[1]) - (c[2] - a[2]) * (b[1] - a[1])
                        gy = (b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2])
                        slope = math.hypot(gx, gy) / abs(det) * 2 / N
                        lines.append("%d %d %.6f %.6f" % (px, py, 5 - z, 1e-3 + slope / 4))
    open(out + "/want_%s.txt" % t, "w").write("\n".join(lines) + "\n")
PY
[ -s "$tmp/pose.gltf" ] || { fail "the scene was not written"; finish; }

# depth at T against the expectation: every listed pixel within 1e-3 and a quarter pixel of
# the depth's slope (16 samples spread over the pixel)
# (queued below, lib.sh: queue, and run in one batch with the sample models' renders)
depth_queue() {
    local t=$1 args=()
    [ "$t" = -1 ] || args=(--at "$t")
    queue "depth_$t" render "$tmp/pose.gltf" --mode depth --size 128x128 --spp 16 \
        --compression none --quiet -o "$tmp/depth_$t.exr" "${args[@]}"
}
depth_at() {
    local t=$1
    check_queued "the posed scene renders at $t" 0 "depth_$t"
    check "... without a warning" test ! -s "$tmp/last"
    if python3 - "$TOOL" "$tmp/depth_$t.exr" "$tmp/want_$t.txt" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import exrtool
_, ch = exrtool.read(sys.argv[2])
r, a = ch["R"][1], ch["A"][1]
bad, n = [], 0
for line in open(sys.argv[3]):
    px, py, want, tol = line.split()
    i = int(py) * 128 + int(px)
    got = r[i] / a[i] if a[i] > 0 else float("nan")
    n += 1
    if not abs(got - float(want)) <= float(tol):
        bad.append("(%s, %s) depth %.5f, expected %s" % (px, py, got, want))
print("%d pixels compared, %d off" % (n, len(bad)))
for b in bad[:5]:
    print("  " + b)
sys.exit(1 if bad or n < 200 else 0)
PY
    then pass; else fail "depth at $t differs from the pose computed from the specification"; fi
}
M=${GONIO_ASSETS:-}/gltf
models=()
[ -n "${GONIO_ASSETS:-}" ] && [ -d "$M/CesiumMan" ] &&
    models=(RiggedSimple SimpleSkin CesiumMan AnimatedMorphCube SimpleMorph MorphPrimitivesTest)
for t in -1 0.4 0.75; do depth_queue $t; done
for m in "${models[@]}"; do
    queue "$m" render "$M/$m/glTF/$m.gltf" --at 0.7 --size 24x24 --spp 1 --quiet -o "$tmp/$m.exr"
done
run_queue

depth_at -1   # the nodes' own transforms and the mesh's weights
depth_at 0.4
depth_at 0.75

# ---- the checks: each broken variant is refused, naming the JSON path ----------------------
python3 - "$tmp" <<'PY'
import json, sys
out = sys.argv[1]
base = json.load(open(out + "/pose.gltf"))
def variant(name, edit):
    d = json.loads(json.dumps(base))
    edit(d)
    json.dump(d, open("%s/bad_%s.gltf" % (out, name), "w"))
def add_acc(d, **a):
    d["accessors"].append(a)
    return len(d["accessors"]) - 1
prim = lambda d, m: d["meshes"][m]["primitives"][0]
variant("joint_index", lambda d: d["skins"][0].update(joints=[2]))
variant("target_count", lambda d: prim(d, 0)["targets"][0].update(
    POSITION=add_acc(d, bufferView=d["accessors"][2]["bufferView"], componentType=5126, type="VEC3", count=3)))
variant("target_type", lambda d: prim(d, 0)["targets"][0].update(
    POSITION=add_acc(d, bufferView=d["accessors"][2]["bufferView"], componentType=5126, type="VEC4", count=3)))
variant("weights_type", lambda d: d["animations"][0]["samplers"][0].update(
    output=add_acc(d, bufferView=d["accessors"][7]["bufferView"], componentType=5126, type="VEC3", count=4)))
variant("weights_count", lambda d: d["animations"][0]["samplers"][0].update(
    output=add_acc(d, bufferView=d["accessors"][7]["bufferView"], componentType=5126, type="SCALAR", count=6)))
variant("mesh_weights", lambda d: d["meshes"][0].update(weights=[1, 0, 0]))
variant("node_weights", lambda d: d["nodes"][0].update(weights=[1]))
variant("targets_differ", lambda d: d["meshes"][0]["primitives"].append(
    {"attributes": {"POSITION": 0}, "indices": 1, "targets": [{"POSITION": 2}]}))
variant("joints_alone", lambda d: prim(d, 1)["attributes"].update(JOINTS_1=prim(d, 1)["attributes"]["JOINTS_0"]))
variant("no_joints", lambda d: d["nodes"][0].update(skin=0))
variant("ibm_type", lambda d: d["skins"][0].update(inverseBindMatrices=d["meshes"][1]["primitives"][0]["attributes"]["WEIGHTS_0"]))
variant("ibm_count", lambda d: d["skins"][0].update(joints=[2, 3, 0]))
variant("joint_twice", lambda d: d["skins"][0].update(joints=[2, 2]))
variant("joint_json", lambda d: d["skins"][0].update(joints=[2, 1.5]))
variant("target_json", lambda d: prim(d, 0)["targets"][0].update(POSITION=99))
variant("weights_channel", lambda d: d["animations"][0]["channels"][0]["target"].update(node=1))
PY
A=$tmp/bad_
bad() {
    check_fails "$2" 1 "$G" info "$A$1.gltf"
    check "... naming it: $3" grep -qF -- "$3" "$tmp/last"
}
bad joint_index "a joint index beyond the skin's joints" \
    "meshes[1].primitives[0].attributes.JOINTS_0: vertex 2 names joint 1, but skins[0] (of nodes[1]) has 1 joints"
bad target_count "a target with another vertex count" \
    "meshes[0].primitives[0].targets[0].POSITION: accessor 15 has 3 elements, but the primitive has 4 vertices"
bad target_type "a target of VEC4" "meshes[0].primitives[0].targets[0].POSITION: accessor 15 (VEC4"
bad weights_type "a weights sampler of VEC3" "animations[0].samplers[0].output: accessor 15"
bad weights_count "a weights sampler with too few values" \
    "animations[0].samplers[0].output: accessor 15 has 6 values, but 2 key(s) x 3"
bad mesh_weights "mesh weights that do not match the targets" "meshes[0].weights: 3 weights for 2 morph targets"
bad node_weights "node weights that do not match the targets" "nodes[0].weights: 1 weights for the 2 morph targets"
bad targets_differ "primitives with different numbers of targets" "meshes[0].primitives[1].targets: 1 morph targets"
bad joints_alone "JOINTS_1 without WEIGHTS_1" "meshes[1].primitives[0].attributes.JOINTS_1: has no WEIGHTS_1"
bad no_joints "a skin on a mesh without joints" "nodes[0].skin: meshes[0].primitives[0] has no JOINTS_0"
bad ibm_type "inverse bind matrices that are not MAT4" "skins[0].inverseBindMatrices: accessor 11 is VEC4"
bad ibm_count "fewer inverse bind matrices than joints" "skins[0].inverseBindMatrices: accessor 12 has 2 matrices for 3 joints"
bad joint_twice "a joint listed twice" "skins[0].joints[1]: node 2 is listed twice"
bad joint_json "a joint that is no index" "skins[0].joints[1]: 1.5 is not an integer index"
bad target_json "a target naming no accessor" "meshes[0].primitives[0].targets[0].POSITION: 99"
bad weights_channel "weights for a node without targets" "animations[0].channels[0].target: node 1 has no morph targets"

# ---- gonio info, and the sample models --------------------------------------------------------
check "gonio info reads the scene" sh -c "'$G' info '$tmp/pose.gltf' >'$tmp/info'"
check "... and counts its skins, joints and morph targets" \
    grep -qxF "skins          1 (2 joints), morph targets 2 (in 1 mesh(es))" "$tmp/info"
if [ ${#models[@]} -gt 0 ]; then
    for m in "${models[@]}"; do
        check_queued "$m renders at 0.7 s" 0 "$m"
        check "... without a warning" test ! -s "$tmp/last"
    done
else
    echo "  note: no sample models (GONIO_ASSETS): skipped them"
fi
finish
