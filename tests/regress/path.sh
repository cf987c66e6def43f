#!/usr/bin/env bash
# path.sh: whole-program checks of the path tracer: the default mode, its flags, an
# interrupted render writing a valid file with its real spp, and `gonio merge` (the merged
# image is the spp-weighted mean of its inputs, exactly).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=scenes/cornell.gltf

# The fast tier has the cases below that tests/README.md names; the slow tier (lib.sh:
# in_tier) the same checks on more models, estimators, scenes and settings.
if in_tier fast; then
check "path is the default mode" "$G" render $C -o "$tmp/d.exr" --spp 2 --size 32x32 --quiet
exrheader "$tmp/d.exr" >"$tmp/hdr.txt" 2>&1
check "mode recorded as path" grep -q 'gonio:mode (type string): "path"' "$tmp/hdr.txt"
check "--max-depth, --brdf and the variance AOV" "$G" render $C -o "$tmp/v.exr" --spp 4 --size 32x32 \
    --max-depth 3 --brdf torrance-sparrow:exponent=128 --aov variance,albedo --quiet
exrheader "$tmp/v.exr" >"$tmp/hdr.txt" 2>&1
check "variance channels written" grep -q 'variance.R,' "$tmp/hdr.txt"
check_fails "an unknown BRDF model is a usage error" 2 "$G" render $C -o "$tmp/x.exr" --brdf nosuch --quiet
check "the message names the models" grep -q 'torrance-sparrow' "$tmp/last"
check_fails "a missing environment map fails" 1 "$G" render $C -o "$tmp/x.exr" --env "$tmp/none.exr" --quiet
fi
# (an environment map for the checks below, in the slow tier alone too)
[ -e "$tmp/d.exr" ] || "$G" render $C -o "$tmp/d.exr" --spp 2 --size 32x32 --quiet

# The pairs of renders below are compared pixel for pixel. They are queued (lib.sh: queue)
# and rendered in one batch, so that a kernel variant is compiled once for all the pairs that
# use it; each pair's checks run once the queue has.
# base SCENE FLAGS...: queues SCENE's render as it is (3 spp, 24x24, FLAGS, GONIO_WALK_ARRAY as
# set now) once a script; its path is $tmp/base-$base_key.exr.
declare -A base_queued=()
base() {
    base_key=$(printf '%s\n' "${GONIO_WALK_ARRAY:-}" "$@" | md5sum | cut -c1-16)
    if [ -z "${base_queued[$base_key]:-}" ]; then
        base_queued[$base_key]=1
        queue "base-$base_key" ${GONIO_WALK_ARRAY:+GONIO_WALK_ARRAY=$GONIO_WALK_ARRAY} \
            render "$1" -o "$tmp/base-$base_key.exr" --spp 3 --size 24x24 --quiet "${@:2}"
    fi
}
pair_n=0
# pair KIND NAME ENV... -- SCENE FLAGS...: queues SCENE's render as it is and one with the
# environment assignments ENV, compared once the queue has run (KIND: same or interrupted).
pair() {
    local kind=$1 name=$2 env=(); shift 2
    while [ "$1" != -- ]; do env+=("$1"); shift; done
    shift
    pair_n=$((pair_n + 1))
    base "$@"
    queue "two-$pair_n" "${env[@]}" ${GONIO_WALK_ARRAY:+GONIO_WALK_ARRAY=$GONIO_WALK_ARRAY} \
        render "$1" -o "$tmp/two-$pair_n.exr" --spp 3 --size 24x24 --quiet "${@:2}"
    after_queue pair_checks "$kind" "$name" "$base_key" "$pair_n"
}
pair_checks() {
    local kind=$1 name=$2 key=$3 n=$4 one=$tmp/base-$3.exr two=$tmp/two-$4.exr dispatches
    if ! queued_ok "base-$key" "two-$n"; then
        fail "$name (render failed)"; cat "$tmp/queue/base-$key.log" "$tmp/queue/two-$n.log" | sed 's/^/    /' | tail -n 20
    elif [ "$kind" = same ]; then
        check_fails "$name" 0 "$G" diff "$one" "$two" --max-error 0
    else
        check "interrupted paths = whole paths: $name" "$TESTTOOL" same "$one" "$two"
        # the last line: the render's own (a file with lights of its own has a probe render first)
        dispatches=$(sed -n 's/^gonio: debug: \([0-9]*\) dispatch.*/\1/p' "$tmp/queue/two-$n.log" | tail -n 1)
        check "... and some were interrupted ($name: ${dispatches:-no} resuming dispatches)" test "${dispatches:-0}" -gt 0
        check "... none cut short ($name)" sh -c "! grep -q 'internal error\|cut short' '$tmp/queue/two-$n.log'"
    fi
}

# same_pixels WHAT ENV NAME SCENE FLAGS...: a render as it is and one with the environment
# assignment ENV must give identical pixels; the check is named "WHAT: NAME".
same_pixels() {
    local what=$1 env=$2 name=$3; shift 3
    pair same "$what: $name" "$env" -- "$@"
}

# The path kernel is specialised on what the scene needs (GN_FEAT_* in glsl/lib/shared.h):
# removing code must not change a single pixel. Each case renders specialised and with
# every feature (GONIO_ALL_FEATURES) and demands the same image, for every BRDF model, each
# estimator, the AOVs, both kinds of environment, and sample models with textures, normal
# maps, glass, punctual lights and vertex colours.
same_as_unspecialised() { same_pixels "specialised = unspecialised" GONIO_ALL_FEATURES=1 "$@"; }
# Fast: the Cornell box and its AOVs, and sample models with textures, normal maps and
# punctual lights (scene features no unit test specialises); slow: glTF's layers (the lobe
# with the most code), every model of the table and the other glTF settings, and each
# estimator alone. (The unit test brdf.specialised_same checks the same rule on every BSDF
# case's queries in the fast tier; each unspecialised kernel is the costliest compile of the
# suite.)
models=$("$G" brdf --list | cut -d' ' -f1) # every model of the table, at its defaults
layers_models="gltf:roughness=0.4:clearcoat=1:clearcoat-roughness=0.2:sheen-color=0.6,0.4,0.2:sheen-roughness=0.5"
A=${GONIO_ASSETS:-}/gltf
if in_tier fast; then
    same_as_unspecialised "Cornell box" $C
    check "brdf --list names models" test -n "$models"
    same_as_unspecialised "AOVs" $C --aov albedo,normal,depth,variance
    # textures and normal maps; punctual lights
    for m in DamagedHelmet LightsPunctualLamp; do
        f=$A/$m/glTF/$m.gltf
        [ -f "$f" ] && same_as_unspecialised "$m" "$f" --env 0.5
    done
fi
if in_tier slow; then
    for model in $layers_models; do
        same_as_unspecialised "--brdf $model" $C --brdf "$model" --env 0.2
    done
    same_as_unspecialised "an environment map" scenes/teapot.gltf --env "$tmp/d.exr"
    f=${GONIO_ASSETS:-}/asset-generator/Material_MetallicRoughness/Material_MetallicRoughness_01.gltf
    [ -f "$f" ] && same_as_unspecialised "vertex colours (Asset Generator)" "$f" --env 0.5
    same_as_unspecialised "light sampling only" $C --estimator light
    same_as_unspecialised "BSDF sampling only" $C --estimator bsdf
    for model in $models conductor:alpha=0 dielectric:alpha=0.3 \
        gltf:metallic=0.5:roughness=0.02 gltf:transmission=1:roughness=0.4 \
        gltf:roughness=0.4:clearcoat=1:clearcoat-roughness=0.2:sheen-color=0.6,0.4,0.2:sheen-roughness=0.5 \
        gltf:roughness=0:metallic=1:clearcoat=0.7; do
        case " $(echo $layers_models) " in *" $model "*) continue ;; esac
        same_as_unspecialised "--brdf $model" $C --brdf "$model" --env 0.2
    done
    for m in TransmissionRoughnessTest NormalTangentTest; do
        f=$A/$m/glTF/$m.gltf
        [ -f "$f" ] && same_as_unspecialised "$m" "$f" --env 0.5
    done
    # gonio brdf --sphere's kernel is specialised on its material by the same rule
    # (material_features; the fast tier's unit test brdf.specialised_same checks that rule on
    # the BSDF queries): the same pixels as the unspecialised kernel.
    k=0
    for m in "lambert" "dielectric --alpha 0.3" "conductor" \
        "gltf --roughness 0.4 --clearcoat 1 --sheen-color 0.6,0.4,0.2 --anisotropy 0.5 --iridescence 0.5 --transmission 0.5"; do
        k=$((k + 1))
        if "$G" brdf $m --sphere -o "$tmp/ball$k.exr" --size 32x32 --spp 4 2>"$tmp/ball.err" &&
            GONIO_ALL_FEATURES=1 "$G" brdf $m --sphere -o "$tmp/ball$k-all.exr" --size 32x32 --spp 4 2>>"$tmp/ball.err"; then
            check_fails "brdf --sphere specialised = unspecialised: $m" 0 "$G" diff "$tmp/ball$k.exr" "$tmp/ball$k-all.exr" --max-error 0
        else
            fail "brdf --sphere $m (render failed)"; sed 's/^/    /' "$tmp/ball.err"
        fi
    done
fi

# The kernels reach the driver with their specialisation constants folded in by the host
# (src/core/spirv_specialise.h); the driver specialising the module as built
# (GONIO_DRIVER_SPECIALISE) must give the same pixels.
same_as_driver_specialised() { same_pixels "specialised on the host = by the driver" GONIO_DRIVER_SPECIALISE=1 "$@"; }
if in_tier fast; then
    same_as_driver_specialised "Cornell box" $C
    same_as_driver_specialised "Cornell box, --mode phong" $C --mode phong
    f=$A/DamagedHelmet/glTF/DamagedHelmet.gltf
    [ -f "$f" ] && same_as_driver_specialised "DamagedHelmet" "$f" --env 0.5
fi
if in_tier slow; then
    same_as_driver_specialised "teapot, glass" scenes/teapot.gltf --camera 0 --brdf dielectric
    same_as_driver_specialised "Cornell box, AOVs, light sampling only" $C --aov albedo,normal,depth,variance --estimator light
    f=$A/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf
    [ -f "$f" ] && same_as_driver_specialised "LightsPunctualLamp" "$f" --env 0.5
fi

# The walk keeps its stack in registers for trees of up to GN_WALK_REGS_MAX levels
# (glsl/lib/bvh.glsl): every pixel must be what the stack in memory gives (GONIO_WALK_ARRAY=1),
# in the path kernel and the local modes.
same_as_stack_array() { same_pixels "stack in registers = in memory" GONIO_WALK_ARRAY=1 "$@"; }
if in_tier fast; then
    d=$("$G" info $C | awk '$1 == "bvh" && $2 == "depth" {print $3}')
    check "the Cornell box's tree is shallow enough for the register stack (depth $d <= 8)" test "$d" -le 8
    same_as_stack_array "Cornell box" $C
    same_as_stack_array "Cornell box, --mode phong" $C --mode phong
fi
if in_tier slow; then
    same_as_stack_array "Cornell box, light sampling only" $C --estimator light
    same_as_stack_array "Cornell box, --mode gouraud" $C --mode gouraud
fi

# llvmpipe's loop cap: a path whose walk runs out of its SIMD group's loop passes is saved
# and finished by the next dispatch (docs/architecture.md). With the cap lowered
# (GONIO_LOOP_CAP) paths are interrupted and resumed many times, in their rays' and their
# shadow rays' walks, past surfaces cut away, with the stack in registers and in memory:
# every pixel and AOV must be what the render at the normal cap gives, and resuming must
# really have happened (GONIO_DEBUG_RESUMES).
same_interrupted() {
    local name=$1; shift
    pair interrupted "$name" GONIO_LOOP_CAP=3000 GONIO_DEBUG_RESUMES=1 -- "$@"
}
if in_tier fast; then
    same_interrupted "Cornell box" $C
    same_interrupted "Cornell box, AOVs" $C --aov albedo,normal,depth,variance
    GONIO_WALK_ARRAY=1 same_interrupted "Cornell box, GONIO_WALK_ARRAY=1" $C
    same_interrupted "teapot, glass" scenes/teapot.gltf --camera 0 --brdf dielectric
fi
if in_tier slow; then
    f=$A/DamagedHelmet/glTF/DamagedHelmet.gltf
    [ -f "$f" ] && same_interrupted "DamagedHelmet" "$f" --env 0.5
    same_interrupted "Cornell box, environment, --max-depth 6" $C --env 0.3 --max-depth 6 --seed 5
    same_interrupted "teapot, an environment map" scenes/teapot.gltf --env "$tmp/d.exr"
    for m in LightsPunctualLamp TransmissionTest; do
        f=$A/$m/glTF/$m.gltf
        [ -f "$f" ] && same_interrupted "$m" "$f" --env 0.5
    done
    # The teapot's glass paths inside it once ran out of their walk budget and were cut short
    # (a warning, and pixels too dark); now none is (the fast tier: "teapot, glass" above).
    check_fails "the teapot from its camera" 0 "$G" render scenes/teapot.gltf --camera 0 --spp 64 \
        --size 128x128 -o "$tmp/teapot.exr"
    check "... warns of nothing" sh -c "! grep -q warning '$tmp/last'"
fi
run_queue # every pair above, in one batch
in_tier fast || { finish; exit; }

# Ctrl-C: the render stops after the current pass, writes what it has and exits 130.
"$G" render $C -o "$tmp/int.exr" --time 60 --size 32x32 2>"$tmp/int.err" &
pid=$!
check "the render to interrupt is in its passes" wait_for "$tmp/int.err" '^gonio: *[0-9]*%'
kill -INT $pid
wait $pid
check "an interrupted render exits 130" test $? = 130
exrheader "$tmp/int.exr" >"$tmp/hdr.txt" 2>&1
check "the interrupted EXR is readable and has its spp" grep -Eq 'gonio:spp \(type int\): [1-9]' "$tmp/hdr.txt"

# merge: 4 + 12 spp with two seeds; the result weights them 1:3.
# (the renders of the merge checks in one batch)
T=scenes/teapot.gltf
r32() { queue "$1" render "${@:2}" --spp 4 --size 32x32 --aov variance --quiet; }
queue a render $C -o "$tmp/a.exr" --spp 4 --size 32x32 --seed 1 --aov variance --quiet
queue b render $C -o "$tmp/b.exr" --spp 12 --size 32x32 --seed 2 --aov variance --quiet
# merge refuses what cannot be one render: exit 1, a message naming both files and the
# field, no output. Each input below differs from a.exr in one thing only.
r32 scene $T -o "$tmp/i-scene.exr" --seed 3
r32 mode $C -o "$tmp/i-mode.exr" --seed 3 --mode phong
r32 camera $C -o "$tmp/i-camera.exr" --seed 3 --camera frame # 0 is the default
r32 max-depth $C -o "$tmp/i-max-depth.exr" --seed 3 --max-depth 2
r32 env $C -o "$tmp/i-env.exr" --seed 3 --env 0.5
r32 estimator $C -o "$tmp/i-estimator.exr" --seed 3 --estimator light
r32 brdf $C -o "$tmp/i-brdf.exr" --seed 3 --brdf lambert
queue p1 render $C -o "$tmp/p1.exr" --mode phong --spp 2 --size 32x32 --seed 1 --quiet
queue p2 render $C -o "$tmp/p2.exr" --mode phong --spp 2 --size 32x32 --seed 2 --no-shadows --quiet
queue p3 render $C -o "$tmp/p3.exr" --mode phong --spp 2 --size 32x32 --seed 3 --max-depth 2 --quiet
# The same scene from another file (a copy elsewhere, or as .glb) is the same render.
mkdir -p "$tmp/elsewhere" && cp $C "$tmp/elsewhere/box.gltf"
r32 copy "$tmp/elsewhere/box.gltf" -o "$tmp/copy.exr" --seed 3
r32 a2 $C -o "$tmp/a2.exr" --seed 1
# --env studio: gonio's studio besides the scene's own lights. Light adds up, so the teapot
# with its sun and the studio has, channel by channel, the mean of the teapot with its sun
# plus that of the teapot without it (which the studio lights by default).
python3 - scenes/teapot.gltf "$tmp/sunless.gltf" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for n in d["nodes"]:
    n.pop("extensions", None)
d.pop("extensions", None)
d["extensionsUsed"] = [e for e in d.get("extensionsUsed", []) if e != "KHR_lights_punctual"]
json.dump(d, open(sys.argv[2], "w"))
PY
S="--camera 0 --size 48x36 --spp 64 --quiet"
queue st-both render scenes/teapot.gltf -o "$tmp/st-both.exr" $S --env studio
queue st-sun render scenes/teapot.gltf -o "$tmp/st-sun.exr" $S
queue st-studio render "$tmp/sunless.gltf" -o "$tmp/st-studio.exr" --camera 0 --size 48x36 --spp 64
queue st-2 render scenes/teapot.gltf -o "$tmp/st-2.exr" $S --env studio --env-intensity 2
run_queue
check_queued "render seed 1" 0 a
check_queued "render seed 2" 0 b
check "merge" "$G" merge "$tmp/a.exr" "$tmp/b.exr" -o "$tmp/m.exr"
exrheader "$tmp/m.exr" >"$tmp/hdr.txt" 2>&1
check "merged spp is the sum" grep -q 'gonio:spp (type int): 16' "$tmp/hdr.txt"
check_fails "merging different sizes fails" 1 "$G" merge "$tmp/a.exr" "$tmp/d.exr" -o "$tmp/x.exr"
for f in scene mode camera max-depth env estimator brdf; do
    check_queued "other $f" 0 $f
done
for f in scene mode camera max-depth env estimator brdf; do
    field=$f; [ $f = brdf ] && field=scene # --brdf changes the materials: another scene
    check_fails "merge refuses another $f" 1 "$G" merge "$tmp/a.exr" "$tmp/i-$f.exr" -o "$tmp/x.exr"
    check "... naming both files and gonio:$field" sh -c "grep 'a.exr' '$tmp/last' | grep 'i-$f.exr' | grep -q 'gonio:$field differs'"
done
check "no output after a refusal" test ! -e "$tmp/x.exr"
check_queued "phong: seed 1" 0 p1
check_queued "phong: seed 2, no shadows" 0 p2
check_queued "phong: seed 3, --max-depth (unused by phong)" 0 p3
check_fails "merge refuses phong with and without shadows" 1 "$G" merge "$tmp/p1.exr" "$tmp/p2.exr" -o "$tmp/x.exr"
check "... naming gonio:shadows" grep -q 'gonio:shadows differs' "$tmp/last"
check "an option the mode ignores does not keep renders apart" "$G" merge "$tmp/p1.exr" "$tmp/p3.exr" -o "$tmp/p13.exr"
check_queued "render a copy of the scene" 0 copy
check "merge takes the copy" "$G" merge "$tmp/a.exr" "$tmp/copy.exr" -o "$tmp/ac.exr"
# Seeds: a repeated one is an error unless --force; merged files carry their seeds on.
check_queued "render seed 1 again" 0 a2
check_fails "merge refuses a repeated seed" 1 "$G" merge "$tmp/a.exr" "$tmp/a2.exr" -o "$tmp/x.exr"
check "... naming both files and the seed" sh -c "grep 'a.exr' '$tmp/last' | grep 'a2.exr' | grep -q 'seed 1'"
check_fails "merge refuses a seed repeated through a merged file" 1 "$G" merge "$tmp/m.exr" "$tmp/a2.exr" -o "$tmp/x.exr"
check "no output after a seed refusal" test ! -e "$tmp/x.exr"
check "--force merges a repeated seed" "$G" merge --force "$tmp/a.exr" "$tmp/a2.exr" -o "$tmp/f.exr"
check "merged seeds recorded" sh -c "exrheader '$tmp/m.exr' | grep -q 'gonio:seeds (type string): \"1,2\"'"
check "merge a merged file with a new seed" "$G" merge "$tmp/m.exr" "$tmp/copy.exr" -o "$tmp/m2.exr"
check "... seeds and spp add up" sh -c "exrheader '$tmp/m2.exr' | grep -q 'gonio:seeds (type string): \"1,2,3\"' && exrheader '$tmp/m2.exr' | grep -q 'gonio:spp (type int): 20'"
# Sample counts: a total past the header's int is refused (exrstdattr rewrites the header).
check "spp 2^31 - 1 (a)" exrstdattr -int gonio:spp 2147483647 "$tmp/a.exr" "$tmp/big-a.exr"
check "spp 2^31 - 1 (b)" exrstdattr -int gonio:spp 2147483647 "$tmp/b.exr" "$tmp/big-b.exr"
check "spp -4" exrstdattr -int gonio:spp -4 "$tmp/a.exr" "$tmp/neg.exr"
check_fails "merge refuses a total over 2^31 - 1" 1 "$G" merge "$tmp/big-a.exr" "$tmp/big-b.exr" -o "$tmp/x.exr"
check "... saying so" grep -q 'total sample count' "$tmp/last"
check_fails "merge refuses spp -4" 1 "$G" merge "$tmp/neg.exr" "$tmp/b.exr" -o "$tmp/x.exr"
check "... naming the file" grep -q 'neg.exr: gonio:spp -4' "$tmp/last"
check "no output after an spp refusal" test ! -e "$tmp/x.exr"
# Output options: .exr only, --half and --compression as for render.
check_fails "merge -o x.png" 2 "$G" merge "$tmp/a.exr" "$tmp/b.exr" -o "$tmp/x.png"
check "merge --half --compression piz" "$G" merge "$tmp/a.exr" "$tmp/b.exr" -o "$tmp/mh.exr" --half --compression piz
check "... half channels, piz" sh -c "exrheader '$tmp/mh.exr' | grep -q 'R, 16-bit floating' && exrheader '$tmp/mh.exr' | grep -q '^compression (type compression): piz'"
check "... the same image to half precision" "$G" diff "$tmp/mh.exr" "$tmp/m.exr" --max-rel-bias 1e-3 --quiet
# (rendered in the batch above, the scene without its lights written before it)
check_queued "--env studio: render" 0 st-both
check_queued "... its own lights alone" 0 st-sun
check_queued "... the scene without its lights" 0 st-studio
check "... which the studio lights by default" grep -q "has no lights: lit by gonio's studio" "$tmp/last"
# adds_up K IMAGE: IMAGE's channel means are the sun's plus K times the studio's, to 3%,
# and the studio's share is no trace (above a fifth of the sun's)
adds_up() {
    python3 -c "
import subprocess, sys
m = lambda f: [float(x) for x in subprocess.check_output(['$TESTTOOL', 'rgb', f]).split()[1:4]]
k, got, sun, studio = $1, m('$2'), m('$tmp/st-sun.exr'), m('$tmp/st-studio.exr')
want = [s + k * t for s, t in zip(sun, studio)]
print('got', got, 'sun + %g studio' % k, want, 'studio', studio)
sys.exit(0 if all(abs(g - w) <= 0.03 * w and t > 0.2 * s for g, w, s, t in zip(got, want, sun, studio)) else 1)"
}
check "... the studio adds to the scene's lights" adds_up 1 "$tmp/st-both.exr"
check_queued "--env studio --env-intensity 2: render" 0 st-2
check "... no studio announcement when asked for" sh -c "! grep -q 'lit by gonio' '$tmp/last'"
check "... twice the studio's share" adds_up 2 "$tmp/st-2.exr"
finish
