#!/usr/bin/env bash
# films.sh: KHR_materials_iridescence and KHR_materials_diffuse_transmission in the path tracer.
# - a thin sheet of diffuse transmission factor k and colour c (black base, no specular lobe)
#   under a large emitter of radiance Le, seen from the other side by an orthographic camera
#   (black environment): the far side's radiance is k c Le F, F the view factor of the emitter
#   (a square of half-size a at distance h: the parallel-rectangle formula, computed here);
#   it is reached only through light sampling of a light behind the surface and BSDF samples
#   through it;
# - a closed cube of diffuse transmission bounding a medium, an emitter inside: light sampling
#   alone and BSDF sampling alone agree (light samples into the medium are attenuated by it);
# - factors of 0 render bit for bit as the files without the extensions;
# - the specialised kernel gives the unspecialised one's pixels;
# - gonio info shows both, and neither is an unsupported extension;
# - IridescenceSuzanne (when $GONIO_ASSETS has it) renders without warnings, its metallic
#   Suzanne coloured by the film.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
T=$TESTTOOL

write_scenes <<'PY'
import math, sys
import gltf_fixture as gf
out = sys.argv[1]
A, H, LE = 2.0, 1.0, 2.0  # emitter half-size, distance, radiance
def quad(z, a, down):  # the square [-a, a]^2 at height z facing +z (down: -z), as two triangles' corners
    p = [(-a, -a, z), (a, -a, z), (a, a, z), (-a, a, z)]
    return [c for k in ((0, 2, 1, 0, 3, 2) if down else (0, 1, 2, 0, 2, 3)) for c in p[k]]
def write(name, shapes, materials, mag, eye):
    """shapes: (corners, material) each a mesh; an orthographic camera of xmag = ymag = mag at
    node `eye` (its fields)"""
    g = gf.Gltf()
    for m in materials:
        g.material(m)
    nodes = [g.node(mesh=g.mesh(g.primitive(corners, material=m))) for corners, m in shapes]
    g.scene(nodes + [g.node(camera=g.orthographic(mag, mag, 0.01, 100), **eye)])
    g.declare_extensions()
    g.write("%s/%s.gltf" % (out, name))
emitter = lambda le: {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "emissiveFactor": [1, 1, 1],
                      "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": le}}}
def scene(name, sheet_ext, irid=None):
    # double-sided: the camera sees the sheet's back, where the light comes through (a
    # single-sided sheet is culled for camera rays there, as glTF's doubleSided false says)
    sheet = {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1},
             "extensions": dict({"KHR_materials_specular": {"specularFactor": 0}}, **sheet_ext), "doubleSided": True}
    # below the sheet, looking up (+z), or (iridescence) above the emitter's light, looking down
    eye, down = {"translation": [0, 0, -5], "rotation": [0, 1, 0, 0]}, False
    if irid is not None:
        sheet = {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 1, "roughnessFactor": 0.3},
                 "extensions": irid, "doubleSided": True}
        eye, down = {"translation": [0, 0, 0.5]}, True  # the sheet faces the camera: the emitter's light reflected
    write(name, [(quad(0.0, 1.0, down), 0), (quad(H, A, True), 1)], [sheet, emitter(LE)], 0.1, eye)
C = [1.0, 0.5, 0.25]
scene("dt", {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0.6, "diffuseTransmissionColorFactor": C}})
scene("dt0", {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0, "diffuseTransmissionColorFactor": C}})
scene("nodt", {})
scene("irid", {}, {"KHR_materials_iridescence": {"iridescenceFactor": 1, "iridescenceThicknessMaximum": 350}})
scene("irid0", {}, {"KHR_materials_iridescence": {"iridescenceFactor": 0, "iridescenceThicknessMaximum": 350}})
scene("noirid", {}, {})
# A closed cube of diffuse transmission (white, no reflection) bounding a medium, a small emitter
# inside facing the camera: light reaches the camera only through the medium, by light samples
# from the cube's faces into it and by paths that cross it.
def cube_scene(name, volume):
    P, _, I = gf.box([-1.0] * 3, [1.0] * 3)
    ext = {"KHR_materials_specular": {"specularFactor": 0},
           "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1}}
    if volume:
        ext["KHR_materials_volume"] = {"thicknessFactor": 2, "attenuationColor": [0.5, 0.7, 0.9], "attenuationDistance": 0.5}
    shell = {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 1},
             "extensions": ext}
    # the emitter at z = 0.5, facing +z
    write(name, [(gf.unindexed(P, I), 0), (quad(0.5, 0.4, False), 1)], [shell, emitter(4)], 0.3, {"translation": [0, 0, 5]})
cube_scene("dtvol", True)
cube_scene("dtnovol", False)
X = Y = A / H
f = lambda x, y: (x / math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x)) +
                  y / math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))) / (2 * math.pi)
F = 4 * f(X, Y)
open(out + "/dt.ref", "w").write(" ".join("%.9g" % (0.6 * c * LE * F) for c in C) + "\n")
PY

near() { python3 -c "import sys; a, b, t = map(float, sys.argv[1:]); sys.exit(0 if abs(a - b) <= t * (b if b > 0 else 1) else 1)" "$@"; }
means() { "$T" rgb "$1" | awk '{print $2, $3, $4}'; }

# The kernel specialised on the scene's features (GN_FEAT_LAYERS) gives the unspecialised
# pixels. (Slow: each unspecialised kernel is an LLVM compile of every feature; the fast tier
# checks the rule on the film and the diffuse transmission in the unit test
# brdf.specialised_same, and on other layered materials in path.sh.)
if in_tier slow; then
    for s in dt irid; do
        "$G" render "$tmp/$s.gltf" -o "$tmp/$s-a.exr" --env 0.5 --quiet --spp 3 --size 24x24 &&
            GONIO_ALL_FEATURES=1 "$G" render "$tmp/$s.gltf" -o "$tmp/$s-b.exr" --env 0.5 --quiet --spp 3 --size 24x24 ||
            fail "$s: renders"
        check "$s: specialised = unspecialised" "$T" same "$tmp/$s-a.exr" "$tmp/$s-b.exr"
    done
fi
in_tier fast || { finish; exit; }

# The fast tier's renders run in one batch (lib.sh: queue); the checks below read each
# line's status, output ($tmp/last) and image.
P="--env 0 --quiet --spp 64 --size 32x32"
queue dt render "$tmp/dt.gltf" -o "$tmp/dt.exr" $P
for st in light bsdf; do queue "dt-$st" render "$tmp/dt.gltf" -o "$tmp/dt-$st.exr" $P --estimator $st; done
for st in light bsdf; do
    queue "dtvol-$st" render "$tmp/dtvol.gltf" -o "$tmp/dtvol-$st.exr" --env 0 --quiet --spp 512 --size 16x16 --estimator $st
done
queue dtnovol render "$tmp/dtnovol.gltf" -o "$tmp/dtnovol.exr" --env 0 --quiet --spp 64 --size 16x16
for s in dt0 nodt irid0 noirid; do queue "$s" render "$tmp/$s.gltf" -o "$tmp/$s.exr" $P; done
queue irid render "$tmp/irid.gltf" -o "$tmp/irid.exr" $P
S=${GONIO_ASSETS:-}/gltf/IridescenceSuzanne/glTF/IridescenceSuzanne.gltf
[ -f "$S" ] && queue suzanne render "$S" -o "$tmp/suzanne.exr" \
    --look-at 0,0.3,7,0,0,0 --fov 40 --env 0.6,0.6,0.6 --spp 8 --size 96x32 --quiet
run_queue

check "info shows the diffuse transmission" sh -c "'$G' info '$tmp/dt.gltf' | grep -q 'diffuse transmission 0 .* factor 0.6, colour (1, 0.5, 0.25)'"
check "info shows the film" sh -c "'$G' info '$tmp/irid.gltf' | grep -q 'iridescence 0 .* factor 1, film ior 1.3, thickness 350 nm'"
for s in dt irid; do
    check_fails "$s: no unsupported-extension warning" 0 "$G" info "$tmp/$s.gltf"
    check "  (none printed)" sh -c "! grep -q 'unsupported extension' '$tmp/last'"
done

check_queued "sheet: render" 0 dt
got=($(means "$tmp/dt.exr")) ref=($(cat "$tmp/dt.ref"))
for k in 0 1 2; do
    check "sheet: far side's radiance k c Le F, channel $k: ${got[$k]} vs ${ref[$k]}" near "${got[$k]}" "${ref[$k]}" 5e-3
done
# each strategy alone: light sampling of the light behind the surface, BSDF samples through it
for st in light bsdf; do
    check_queued "sheet, $st sampling alone: render" 0 "dt-$st"
    got=($(means "$tmp/dt-$st.exr"))
    check "  channel 0: ${got[0]} vs ${ref[0]}" near "${got[0]}" "${ref[0]}" 1e-2
done
# A medium behind diffuse transmission: a light sample into it is attenuated as a path through
# it is, so light sampling alone and BSDF sampling alone agree (without the medium on the light
# sample's side, light sampling alone is brighter), and the medium darkens the cube.
check "info: the cube of diffuse transmission bounds a medium" sh -c "'$G' info '$tmp/dtvol.gltf' | grep -q 'medium 0'"
for st in light bsdf; do
    check_queued "cube with a medium, $st sampling alone: render" 0 "dtvol-$st"
done
check_queued "cube without the medium: render" 0 dtnovol
gl=($(means "$tmp/dtvol-light.exr")) gb=($(means "$tmp/dtvol-bsdf.exr")) gn=($(means "$tmp/dtnovol.exr"))
for k in 0 1 2; do
    check "  channel $k: light sampling ${gl[$k]} = BSDF sampling ${gb[$k]}" near "${gl[$k]}" "${gb[$k]}" 0.03
done
check "  the medium darkens red (${gb[0]}) below half of no medium's (${gn[0]})" \
    python3 -c "import sys; sys.exit(0 if ${gb[0]} < 0.5 * ${gn[0]} else 1)"
for s in dt0 nodt irid0 noirid; do
    queued_ok "$s" || fail "render $s"
done
check "diffuse transmission 0 is the file without the extension" "$T" same "$tmp/nodt.exr" "$tmp/dt0.exr"
check "iridescence 0 is the file without the extension" "$T" same "$tmp/noirid.exr" "$tmp/irid0.exr"
check_queued "iridescence: render" 0 irid
check_fails "  (the film changes the reflection)" 1 "$T" same "$tmp/noirid.exr" "$tmp/irid.exr"

if [ -f "$S" ]; then
    check_queued "IridescenceSuzanne: renders without warnings" 0 suzanne
    check "  (no warning)" sh -c "! grep -q 'warning' '$tmp/last'"
    check "IridescenceSuzanne: info shows its thickness texture's range" sh -c \
        "'$G' info '$S' | grep -q 'iridescence 2 .* film ior 1.8, thickness 200 - 600 nm (texture G)'"
else
    echo "  note: \$GONIO_ASSETS has no IridescenceSuzanne: its checks skipped"
fi
finish
