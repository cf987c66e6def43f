#!/usr/bin/env bash
# assets.sh: files the project did not write, rendered as a new user would, with no flags
# but the output: every Khronos sample model and every glTF Asset Generator model must
# render (exit 0) and show itself lit: the pixels it covers are not black. A scene without
# lights of its own gets the studio environment (src/scene/environment.h); one with them keeps
# them. Skips when the third-party assets are absent.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
A=${GONIO_ASSETS:-}
[ -n "$A" ] && [ -d "$A/gltf" ] || skip_all "no test assets (GONIO_ASSETS)"

files=()
for d in "$A"/gltf/*/; do # one variant of each model: glTF, else glTF-Binary
    f=$(ls "$d"glTF/*.gltf 2>/dev/null | head -n 1)
    [ -n "$f" ] || f=$(ls "$d"glTF-Binary/*.glb 2>/dev/null | head -n 1)
    [ -n "$f" ] && files+=("$f")
done
for f in "$A"/asset-generator/*/*.gltf; do files+=("$f"); done
[ ${#files[@]} -gt 40 ] || fail "expected the 20 sample models and 36 Asset Generator models, found ${#files[@]}"

# Every eighth model (in the order above, so each set has models in both tiers) is in the
# fast tier, the rest in the slow tier: the same check on each model, in one tier or the
# other. (A render of a sample model costs about 2.5 s of CPU alone: its kernel's compile,
# its textures, its tree; in a batch, models with the same features share the kernel.)
# (the renders in one batch: lib.sh, queue; models that need the same kernel share it)
k=0 models=()
for f in "${files[@]}"; do
    k=$((k + 1))
    if [ $((k % 8)) = 1 ]; then in_tier fast || continue; else in_tier slow || continue; fi
    m=$(basename "$f" | sed 's/\.[^.]*$//')
    queue "$m" render "$f" -o "$tmp/$m.exr" --size 32x32 --spp 4 --quiet
    models+=("$m")
done
run_queue
for m in "${models[@]}"; do
    out="$tmp/$m.exr"
    rc=$(queued "$m")
    if [ "$rc" != 0 ]; then
        fail "$m renders with default flags (exit $rc)"
        sed 's/^/    /' "$tmp/last" | tail -n 5
        continue
    fi
    pass
    read -r _ covered _ mean _ _ <<<"$("$TESTTOOL" stats "$out")"
    # Lit: the mean luminance over the model's own pixels is well above black (the darkest,
    # Material_MetallicRoughness_00's black metal, reads about 0.05 under the studio).
    if awk -v c="$covered" -v m="$mean" 'BEGIN {exit !(c > 0 && m > 0.01)}'; then
        pass
    else
        fail "$m with default flags is black or empty (covered $covered pixels, mean $mean)"
    fi
done
finish
