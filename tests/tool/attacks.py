#!/usr/bin/env python3
"""attacks.py OUT_DIR: hostile scenes for the loaders of skins, morph targets and instancing,
each written to OUT_DIR/NAME.gltf, and OUT_DIR/expect.txt: one line a scene,

    NAME STATUS MESSAGE

the exit status `gonio info` must give and a fixed string its stderr must hold ("-" for
none: then it must print no warning either). tests/regress/hostile.sh checks each, under a
time limit; tests/fuzz/run.sh seeds the scene fuzzer with them. Every one is a file a few
hundred bytes long that tries to make the loader hang, allocate without bound, crash, read
a non-finite number into the scene or misread silently."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_fixture as gf  # noqa: E402

TRI = [0, 0, 0, 1, 0, 0, 0, 1, 0]


def skinned_triangle(g, weights=(1, 0, 0, 0)):
    """a triangle whose three vertices a skin's joint 0 moves with these weights"""
    pos = g.accessor(TRI, "VEC3", bounds=True)
    j = g.accessor(gf.pack(gf.UNSIGNED_BYTE, [0] * 12), "VEC4", component=gf.UNSIGNED_BYTE, count=3)
    w = g.accessor(list(weights) * 3, "VEC4")
    return g.mesh({"attributes": {"POSITION": pos, "JOINTS_0": j, "WEIGHTS_0": w}})


def main(out):
    os.makedirs(out, exist_ok=True)
    expect = []

    def write(name, g, status, message):
        g.write(os.path.join(out, name + ".gltf"))
        expect.append("%s %d %s" % (name, status, message))

    # ---- skins ------------------------------------------------------------------------------
    for name, ibm, status, msg in (
            ("skin-ibm-singular", [0] * 16, 0, "skins[0].inverseBindMatrices: joint 0's matrix is singular"),
            ("skin-ibm-nan", [float("nan")] * 16, 1, "the joint's matrix (node 0's world transform x its inverse bind matrix) is not finite"),
            ("skin-ibm-huge", [1e38] * 12 + [1e38, 1e38, 1e38, 1], 1, "no triangles")):
        g = gf.Gltf()
        m = skinned_triangle(g)
        joint = g.node()
        g.add("skins", {"joints": [joint], "inverseBindMatrices": g.accessor(ibm, "MAT4")})
        g.scene([g.node(mesh=m, skin=0), joint])
        write(name, g, status, msg)
    for name, w, msg in (("skin-weights-small", 0.2, "joint weights that do not sum to one (renormalised)"),
                         ("skin-weights-huge", 1e30, "joint weights that do not sum to one (renormalised)")):
        g = gf.Gltf()
        m = skinned_triangle(g, (w, 0, 0, 0))
        joint = g.node()
        g.add("skins", {"joints": [joint]})
        g.scene([g.node(mesh=m, skin=0), joint])
        write(name, g, 0, msg)
    g = gf.Gltf()  # a joint no scene root reaches: its own transform still moves the mesh
    m = skinned_triangle(g)
    g.add("skins", {"joints": [g.node(translation=[5, 0, 0])]})
    g.scene([g.node(mesh=m, skin=0)])
    write("skin-joint-outside", g, 0, "-")
    g = gf.Gltf()  # joints in a loop of children, the skeleton on it
    m = skinned_triangle(g)
    a = g.node()
    b = g.node(children=[a])
    g.doc["nodes"][a]["children"] = [b]
    g.add("skins", {"joints": [a], "skeleton": b})
    g.scene([g.node(mesh=m, skin=0)])
    write("skin-cycle", g, 1, "is part of a node loop")
    g = gf.Gltf()
    m = skinned_triangle(g)
    g.add("skins", {"joints": [99]})
    g.scene([g.node(mesh=m, skin=0)])
    write("skin-joint-missing", g, 1, "skins[0].joints[0]: 99 does not exist")
    g = gf.Gltf()  # 70,000 joints (more than a 16-bit JOINTS index reaches)
    m = skinned_triangle(g)
    g.add("skins", {"joints": [g.node() for _ in range(70000)]})
    g.scene([g.node(mesh=m, skin=0)])
    write("skin-70000-joints", g, 0, "-")

    # ---- morph targets -----------------------------------------------------------------------
    g = gf.Gltf()  # 5,000 targets sharing one displacement, all weighted
    pos = g.accessor(TRI, "VEC3", bounds=True)
    d = g.accessor([0, 0, 0.001] * 3, "VEC3")
    g.scene([g.node(mesh=g.mesh({"attributes": {"POSITION": pos}, "targets": [{"POSITION": d}] * 5000},
                                weights=[1.0] * 5000))])
    write("morph-5000-targets", g, 0, "-")
    g = gf.Gltf()  # weights that carry the positions past float range
    pos = g.accessor(TRI, "VEC3", bounds=True)
    d = g.accessor([0, 0, 3e38] * 3, "VEC3")
    g.scene([g.node(mesh=g.mesh({"attributes": {"POSITION": pos}, "targets": [{"POSITION": d}] * 4},
                                weights=[1e30] * 4))])
    write("morph-to-infinity", g, 1, "with non-finite or huge (|x| > 1e15) vertex positions")

    # ---- instancing ----------------------------------------------------------------------------
    g = gf.Gltf()  # 10^9 instances asked by one accessor of no buffer view
    m = g.mesh({"attributes": {"POSITION": g.accessor(TRI, "VEC3", bounds=True)}})
    many = g.add("accessors", {"componentType": gf.FLOAT, "count": 1000000000, "type": "VEC3"})
    g.use("EXT_mesh_gpu_instancing")
    g.scene([g.node(mesh=m, extensions={"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": many}}})])
    write("instances-1e9", g, 1, "count 1000000000 is out of range")
    g = gf.Gltf()  # 10^9 by sharing: 1,000 nodes each placing one accessor's 10^6 instances
    m = g.mesh({"attributes": {"POSITION": g.accessor(TRI, "VEC3", bounds=True)}})
    million = g.add("accessors", {"componentType": gf.FLOAT, "count": 1000000, "type": "VEC3"})
    g.use("EXT_mesh_gpu_instancing")
    g.scene([g.node(mesh=m, extensions={"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": million}}})
             for _ in range(1000)])
    write("instances-1e9-shared", g, 1, "more than the 1048576 a scene may have")
    g = gf.Gltf()  # TRANSLATION and SCALE disagree on the count
    m = g.mesh({"attributes": {"POSITION": g.accessor(TRI, "VEC3", bounds=True)}})
    t = g.accessor([0, 0, 0, 1, 0, 0, 2, 0, 0], "VEC3")
    s = g.accessor([1, 1, 1, 1, 1, 1], "VEC3")
    g.use("EXT_mesh_gpu_instancing")
    g.scene([g.node(mesh=m, extensions={"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t, "SCALE": s}}})])
    write("instances-count-mismatch", g, 1, "accessor 1 has 3 elements, SCALE's has 2")

    with open(os.path.join(out, "expect.txt"), "w") as f:
        f.write("\n".join(expect) + "\n")


if __name__ == "__main__":
    main(sys.argv[1])
