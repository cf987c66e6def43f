#!/usr/bin/env bash
# path.sh: whole-program checks of the path tracer: the default mode, its flags, an
# interrupted render writing a valid file with its real spp, and `gonio merge` (the merged
# image is the spp-weighted mean of its inputs, exactly).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=scenes/cornell.gltf

check "path is the default mode" "$G" render $C -o "$tmp/d.exr" --spp 2 --size 32x32 --quiet
exrheader "$tmp/d.exr" >"$tmp/hdr.txt" 2>&1
check "mode recorded as path" grep -q 'gonio:mode (type string): "path"' "$tmp/hdr.txt"
check "--max-depth, --brdf and the variance AOV" "$G" render $C -o "$tmp/v.exr" --spp 4 --size 32x32 \
    --max-depth 3 --brdf torrance-sparrow:exponent=128 --aov variance,albedo --quiet
exrheader "$tmp/v.exr" >"$tmp/hdr.txt" 2>&1
check "variance channels written" grep -q 'variance.R,' "$tmp/hdr.txt"
check_fails "an unknown BRDF model is a usage error" 1 "$G" render $C -o "$tmp/x.exr" --brdf nosuch --quiet
check "the message names the models" grep -q 'torrance-sparrow' "$tmp/last"
check_fails "a missing environment map fails" 1 "$G" render $C -o "$tmp/x.exr" --env "$tmp/none.exr" --quiet

# same_pixels WHAT ENV NAME SCENE FLAGS...: a render as it is and one with the environment
# assignment ENV must give identical pixels; the check is named "WHAT: NAME".
same_pixels() {
    local what=$1 env=$2 name=$3 scene=$4; shift 4
    if "$G" render "$scene" -o "$tmp/one.exr" --spp 3 --size 24x24 --quiet "$@" 2>"$tmp/spec.err" &&
        env "$env" "$G" render "$scene" -o "$tmp/two.exr" --spp 3 --size 24x24 --quiet "$@" \
            2>>"$tmp/spec.err"; then
        check_fails "$what: $name" 0 "$G" diff "$tmp/one.exr" "$tmp/two.exr" --max-error 0
    else
        fail "$what: $name (render failed)"; sed 's/^/    /' "$tmp/spec.err"
    fi
}

# The path kernel is specialised on what the scene needs (GN_FEAT_* in glsl/shared.h):
# removing code must not change a single pixel. Each case renders specialised and with
# every feature (GONIO_ALL_FEATURES) and demands the same image, for every BRDF model, each
# estimator, the AOVs, both kinds of environment, and sample models with textures, normal
# maps, glass, punctual lights and vertex colours.
same_as_unspecialised() { same_pixels "specialised = unspecialised" GONIO_ALL_FEATURES=1 "$@"; }
same_as_unspecialised "Cornell box" $C
for model in lambert mirror phong blinn-phong torrance-sparrow beckmann ggx conductor \
    conductor:alpha=0 dielectric dielectric:alpha=0.3 \
    gltf:metallic=0.5:roughness=0.02 gltf:transmission=1:roughness=0.4; do
    same_as_unspecialised "--brdf $model" $C --brdf "$model" --env 0.2
done
same_as_unspecialised "light sampling only" $C --estimator light
same_as_unspecialised "BSDF sampling only" $C --estimator bsdf
same_as_unspecialised "AOVs" $C --aov albedo,normal,depth,variance
same_as_unspecialised "an environment map" scenes/teapot.gltf --env "$tmp/d.exr"
A=${GONIO_ASSETS:-}/gltf
for m in DamagedHelmet TransmissionRoughnessTest LightsPunctualLamp NormalTangentTest; do
    f=$A/$m/glTF/$m.gltf
    [ -f "$f" ] && same_as_unspecialised "$m" "$f" --env 0.5
done
f=${GONIO_ASSETS:-}/asset-generator/Material_MetallicRoughness/Material_MetallicRoughness_01.gltf
[ -f "$f" ] && same_as_unspecialised "vertex colours (Asset Generator)" "$f" --env 0.5

# The walk keeps its stack in registers for trees of up to GN_WALK_REGS_MAX levels
# (glsl/bvh.glsl): every pixel must be what the stack in memory gives (GONIO_WALK_ARRAY=1),
# in the path kernel and the local modes.
same_as_stack_array() { same_pixels "stack in registers = in memory" GONIO_WALK_ARRAY=1 "$@"; }
d=$("$G" info $C | awk '$1 == "bvh" && $2 == "depth" {print $3}')
check "the Cornell box's tree is shallow enough for the register stack (depth $d <= 8)" test "$d" -le 8
same_as_stack_array "Cornell box" $C
same_as_stack_array "Cornell box, light sampling only" $C --estimator light
same_as_stack_array "Cornell box, --mode phong" $C --mode phong
same_as_stack_array "Cornell box, --mode gouraud" $C --mode gouraud

# Ctrl-C: the render stops after the current pass, writes what it has and exits 130.
"$G" render $C -o "$tmp/int.exr" --time 60 --size 32x32 --quiet &
pid=$!
sleep 3
kill -INT $pid
wait $pid
check "an interrupted render exits 130" test $? = 130
exrheader "$tmp/int.exr" >"$tmp/hdr.txt" 2>&1
check "the interrupted EXR is readable and has its spp" grep -Eq 'gonio:spp \(type int\): [1-9]' "$tmp/hdr.txt"

# merge: 4 + 12 spp with two seeds; the result weights them 1:3.
check "render seed 1" "$G" render $C -o "$tmp/a.exr" --spp 4 --size 32x32 --seed 1 --aov variance --quiet
check "render seed 2" "$G" render $C -o "$tmp/b.exr" --spp 12 --size 32x32 --seed 2 --aov variance --quiet
check "merge" "$G" merge "$tmp/a.exr" "$tmp/b.exr" -o "$tmp/m.exr"
exrheader "$tmp/m.exr" >"$tmp/hdr.txt" 2>&1
check "merged spp is the sum" grep -q 'gonio:spp (type int): 16' "$tmp/hdr.txt"
check_fails "merging different sizes fails" 1 "$G" merge "$tmp/a.exr" "$tmp/d.exr" -o "$tmp/x.exr"
finish
