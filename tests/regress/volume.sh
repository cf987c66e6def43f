#!/usr/bin/env bash
# volume.sh: KHR_materials_volume and KHR_materials_dispersion in the path tracer, against
# analytic answers. Boxes seen head-on by an orthographic camera against a constant white
# environment: every ray crosses the same lengths, so a pixel's expectation is exact.
# - index 1 (no Fresnel, no randomness): a slab of thickness d gives exp(-sigma d) exactly,
#   sigma = -ln(attenuationColor) / attenuationDistance per channel;
# - index 1.5: all light ends in the environment but what the slab absorbs, so the image is
#   R + T^2 tau / (1 - R tau), R = ((n-1)/(n+1))^2, T = 1 - R, tau = exp(-sigma d): the sum
#   over the internal reflections, computed here;
# - nested media: a box of liquid inside a box of glass, and a glass shell holding a liquid
#   that overlaps its inner wall ("touching"): exp(-sigma_g d_g - sigma_l d_l) with the
#   lengths the interior stack assigns (docs/path-tracing.md); and the index 1.5 slab's
#   medium inside glass of the same index, whose answer is the slab's (an index ratio of 1:
#   no reflection at the inner faces);
# - dispersion: a sphere in front of a white bar: dispersion separates the channels' images
#   (centroids), each as the same sphere without dispersion at that channel's index places
#   it, dispersion 0 is bit for bit the file without the extension;
# - bad values warn; and (the slow tier) the specialised kernel gives the unspecialised one's pixels.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
T=$TESTTOOL

write_scenes <<'PY'
import math, sys
import gltf_fixture as gf
out = sys.argv[1]
def scene(name, shapes, materials, camera, eye=(0, 0, 5)):
    """shapes: (corners, material), the corners of triangles (a flat list) one primitive of
    its own node each, all in one POSITION accessor"""
    g = gf.Gltf()
    pos = [c for corners, _ in shapes for c in corners]
    position = g.accessor(pos, "VEC3", bounds=True, target=gf.ARRAY_BUFFER)
    indices = g.view(gf.pack(gf.UNSIGNED_INT, range(len(pos) // 3)), target=gf.ELEMENT_ARRAY_BUFFER)
    for m in materials:
        g.material(m)
    nodes, first = [], 0
    for corners, mat in shapes:
        n = len(corners) // 3
        idx = g.accessor(None, "SCALAR", gf.UNSIGNED_INT, count=n, view=indices, byteOffset=4 * first)
        nodes.append(g.node(mesh=g.mesh({"attributes": {"POSITION": position}, "indices": idx, "material": mat})))
        first += n
    g.scene(nodes + [g.node(camera=g.add("cameras", camera), translation=list(eye))])
    g.declare_extensions()
    g.write("%s/%s.gltf" % (out, name))
def box(h, inward=False):  # [-h, h]'s corners, outward-facing unless inward
    P, _, I = gf.box([-x for x in h], h)
    if inward:
        I = [I[t + k] for t in range(0, len(I), 3) for k in (0, 2, 1)]
    return gf.unindexed(P, I)
def sphere(r, n=48):
    m = n // 2
    V = lambda i, j: [r * math.sin(math.pi * i / m) * math.cos(2 * math.pi * j / n),
                      r * math.sin(math.pi * i / m) * math.sin(2 * math.pi * j / n), r * math.cos(math.pi * i / m)]
    tris = [t for i in range(m) for j in range(n) for k, t in enumerate(((V(i, j), V(i + 1, j), V(i, j + 1)),
            (V(i + 1, j), V(i + 1, j + 1), V(i, j + 1)))) if (k == 0 and i > 0) or (k == 1 and i < m - 1)]
    return [c for t in tris for p in t for c in p]
def glass(ior, color=None, dist=None, dispersion=None, volume=True):
    e = {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": ior}}
    if volume:
        e["KHR_materials_volume"] = {"thicknessFactor": 1}
        if color: e["KHR_materials_volume"]["attenuationColor"] = color
        if dist: e["KHR_materials_volume"]["attenuationDistance"] = dist
    if dispersion is not None:
        e["KHR_materials_dispersion"] = {"dispersion": dispersion}
    return {"pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0}, "extensions": e}
ortho = {"type": "orthographic", "orthographic": {"xmag": 0.2, "ymag": 0.2, "znear": 0.01, "zfar": 100}}
A, D = [0.5, 0.25, 0.8], 2.0          # the slabs' medium (thickness 1)
scene("slab1", [(box([1, 1, 0.5]), 0)], [glass(1, A, D)], ortho)
scene("slab15", [(box([1, 1, 0.5]), 0)], [glass(1.5, A, D)], ortho)
Ag, Dg, Al, Dl = [0.9, 0.6, 0.3], 1.0, [0.2, 0.5, 0.9], 0.5   # glass, liquid
scene("nested", [(box([1, 1, 1]), 0), (box([0.5, 0.5, 0.5]), 1)], [glass(1, Ag, Dg), glass(1, Al, Dl)], ortho)
# the same medium as slab15 inside a non-absorbing glass of the same index: the inner
# faces are no interface (index ratio 1), so the answer is slab15's
scene("nested15", [(box([1, 1, 1]), 0), (box([0.5, 0.5, 0.5]), 1)], [glass(1.5), glass(1.5, A, D)], ortho)
e = 0.001  # the liquid overlaps the shell's inner wall by e
scene("touching", [(box([1, 1, 1]), 0), (box([0.5, 0.5, 0.5], True), 0), (box([0.5 + e] * 3), 1)],
      [glass(1, Ag, Dg), glass(1, Al, Dl)], ortho)
light = {"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}}
bar = [0.1, -3, -3, 0.5, -3, -3, 0.5, 3, -3, 0.1, -3, -3, 0.5, 3, -3, 0.1, 3, -3]
persp = {"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.01}}
def prism(name, m):
    scene(name, [(sphere(1), 0), (bar, 1)], [m, light], persp, (0, 0, 4))
prism("disp1", glass(1.5, dispersion=1))          # Abbe number 20
prism("disp0", glass(1.5, dispersion=0))
prism("nodisp", glass(1.5))
prism("thin0", glass(1.5, dispersion=0, volume=False))
prism("plain", glass(1.5, volume=False))
# glTF's n(lambda) = n_d + (n_d - 1) / V (523655 / lambda^2 - 1.5168) at C (656.3 nm) and F (486.1 nm)
for c, lam in (("R", 656.3), ("B", 486.1)):
    prism("ior" + c, glass(1.5 + 0.5 / 20 * (523655 / lam ** 2 - 1.5168)))
bad = glass(1.5, [2, 0, 0], -1)
scene("bad", [(box([1, 1, 0.5]), 0)], [bad], ortho)
# the references
tau = lambda c, d: [x ** (d / D) for x in c]
R = 0.2 ** 2
ref = {"slab1": tau(A, 1), "slab15": [R + (1 - R) ** 2 * t / (1 - R * t) for t in tau(A, 1)],
       "nested": [g ** (1 / Dg) * l ** (1 / Dl) for g, l in zip(Ag, Al)],
       "touching": [g ** ((1 - e) / Dg) * l ** ((1 + e) / Dl) for g, l in zip(Ag, Al)],
       "slab15-single": [R + (1 - R) ** 2 * t for t in tau(A, 1)]}
for k, v in ref.items():
    open("%s/%s.ref" % (out, k), "w").write(" ".join("%.9g" % x for x in v) + "\n")
PY

# near A B TOL: |A - B| <= TOL (relative to B when B > 0)
near() { python3 -c "import sys; a, b, t = map(float, sys.argv[1:]); sys.exit(0 if abs(a - b) <= t * (b if b > 0 else 1) else 1)" "$@"; }
# channels FILE.exr: "R G B" means
means() { "$T" rgb "$1" | awk '{print $2, $3, $4}'; }
cx() { "$T" rgb "$1" | awk -v k="$2" '{print $(6 + k)}'; }
check_means() { # WHAT EXR REF TOL
    local got ref k
    got=($(means "$2")) ref=($(cat "$3"))
    for k in 0 1 2; do
        check "$1: channel $k ${got[$k]} vs ${ref[$k]}" near "${got[$k]}" "${ref[$k]}" "$4"
    done
}

# The slow tier (lib.sh, in_tier): the kernel specialised on the scene's features
# (GN_FEAT_VOLUME) gives the unspecialised kernel's pixels. (The fast tier
# compares the two kernels in path.sh and, on every BSDF setting, in brdf.specialised_same.)
if in_tier slow; then
    for s in nested disp1; do
        queue "$s-a" render "$tmp/$s.gltf" -o "$tmp/$s-a.exr" --env 1 --quiet --spp 3 --size 24x24
        queue "$s-b" GONIO_ALL_FEATURES=1 render "$tmp/$s.gltf" -o "$tmp/$s-b.exr" --env 1 --quiet --spp 3 --size 24x24
    done
    run_queue
    for s in nested disp1; do
        queued_ok "$s-a" "$s-b" || fail "$s: renders"
        check "$s: specialised = unspecialised" "$T" same "$tmp/$s-a.exr" "$tmp/$s-b.exr"
    done
fi
in_tier fast || { finish; exit; }

check "info reads the volume" sh -c "'$G' info '$tmp/slab1.gltf' | grep -q 'medium 0 .* volume attenuation (0.5, 0.25, 0.8) distance 2 (sigma_a 0.346574, 0.693147, 0.111572)'"
check_fails "no unsupported-extension warning" 0 "$G" info "$tmp/disp1.gltf"
check "  (none printed)" sh -c "! grep -q 'unsupported extension' '$tmp/last'"
check_fails "bad values warn" 0 "$G" info "$tmp/bad.gltf"
check "  attenuationDistance" grep -q "bad.gltf: material 0: attenuationDistance -1 must be positive" "$tmp/last"
check "  attenuationColor" grep -q "bad.gltf: material 0: attenuationColor must be 3 numbers in \[0, 1\]" "$tmp/last"

F="--env 1 --quiet"
P="--env 0 --quiet --spp 64 --size 96x96"
# (every render below in one batch: lib.sh, queue; the references are computed here)
queue slab1 render "$tmp/slab1.gltf" -o "$tmp/slab1.exr" $F --spp 2 --size 16x16
queue slab15 render "$tmp/slab15.gltf" -o "$tmp/slab15.exr" $F --spp 64 --size 64x64
queue nested15 render "$tmp/nested15.gltf" -o "$tmp/nested15.exr" $F --spp 64 --size 64x64
for s in nested touching; do queue "$s" render "$tmp/$s.gltf" -o "$tmp/$s.exr" $F --spp 64 --size 64x64; done
for s in disp1 disp0 nodisp thin0 plain iorR iorB; do queue "$s" render "$tmp/$s.gltf" -o "$tmp/$s.exr" $P; done
run_queue

# Index 1: no Fresnel, no roulette before depth 3: the same number in every pixel, to float precision.
check_queued "slab, index 1: render" 0 slab1
check_means "slab, index 1: exp(-sigma d)" "$tmp/slab1.exr" "$tmp/slab1.ref" 1e-5
# Index 1.5: Fresnel at both faces and every internal reflection (a Monte Carlo estimate:
# 262144 paths, standard error about 1e-4 relative).
check_queued "slab, index 1.5: render" 0 slab15
check_means "slab, index 1.5: R + T^2 tau / (1 - R tau)" "$tmp/slab15.exr" "$tmp/slab15.ref" 2e-3
check_fails "  (the single pass alone is not it)" 1 near "$(means "$tmp/slab15.exr" | awk '{print $1}')" "$(awk '{print $1}' "$tmp/slab15-single.ref")" 2e-3
check_queued "glass around a medium of its index: render" 0 nested15
check_means "glass around a medium of its index: no inner interface" "$tmp/nested15.exr" "$tmp/slab15.ref" 2e-3
for s in nested touching; do
    check_queued "$s media: render" 0 "$s"
    check_means "$s media: exp(-sigma_g d_g - sigma_l d_l)" "$tmp/$s.exr" "$tmp/$s.ref" 3e-3
done

# Dispersion: a white bar seen through a sphere of index 1.5.
for s in disp1 disp0 nodisp thin0 plain iorR iorB; do
    queued_ok "$s" || { fail "render $s"; sed 's/^/    /' "$tmp/last"; }
done
check "dispersion 0 is the file without the extension" "$T" same "$tmp/nodisp.exr" "$tmp/disp0.exr"
check "  (without a volume too)" "$T" same "$tmp/plain.exr" "$tmp/thin0.exr"
check "without dispersion the channels are equal" test "$(cx "$tmp/disp0.exr" 0)" = "$(cx "$tmp/disp0.exr" 2)"
rx=$(cx "$tmp/disp1.exr" 0) bx=$(cx "$tmp/disp1.exr" 2)
check "dispersion separates red ($rx) from blue ($bx)" python3 -c "import sys; sys.exit(0 if $bx - $rx > 0.25 else 1)"
check "red lies where index n_R puts it ($(cx "$tmp/iorR.exr" 0))" near "$rx" "$(cx "$tmp/iorR.exr" 0)" 0.003
check "blue lies where index n_B puts it ($(cx "$tmp/iorB.exr" 2))" near "$bx" "$(cx "$tmp/iorB.exr" 2)" 0.003
check "red's brightness is n_R's" near "$(means "$tmp/disp1.exr" | awk '{print $1}')" "$(means "$tmp/iorR.exr" | awk '{print $1}')" 0.03
check "blue's brightness is n_B's" near "$(means "$tmp/disp1.exr" | awk '{print $3}')" "$(means "$tmp/iorB.exr" | awk '{print $3}')" 0.03

finish
