#!/usr/bin/env bash
# same_images.sh OLD_GONIO NEW_GONIO [OUT_DIR]: renders the same scenes with two builds of
# gonio and compares every pixel, bit for bit: the check of a change that must not change
# any image (a restructuring). The scenes: the project's own (scenes/, gonio scene, the
# teapot), every glTF of $GONIO_ASSETS (Khronos sample models, glTF Asset Generator sets),
# in path mode with the default environment rule, and the Cornell box in every mode; small
# sizes and sample counts, so that the whole set takes minutes. A scene that one build
# refuses must be refused by the other too. Prints one line per difference and a summary;
# exit 1 when any image differs.
set -u
OLD=$(realpath "$1") NEW=$(realpath "$2")
root=$(cd "$(dirname "$0")/../.." && pwd)
out=${3:-$(mktemp -d)}
mkdir -p "$out"
A=${GONIO_ASSETS:-$root/../shared/assets}
export VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)}
cd "$root"

"$NEW" scene cornell -o "$out/cornell-gen.gltf" && "$NEW" teapot --level 3 -o "$out/teapot.gltf" || exit 1
scenes=(scenes/*.gltf "$out/cornell-gen.gltf" "$out/teapot.gltf")
if [ -d "$A" ]; then
    while IFS= read -r f; do scenes+=("$f"); done < <(find "$A/gltf" "$A/asset-generator" \( -name '*.gltf' -o -name '*.glb' \) | sort)
else
    echo "note: $A is absent: only the project's own scenes are compared"
fi

same=0 differ=0 refused=0 n=0
compare() { # compare NAME ARGS...: render with both builds, compare
    local name=$1; shift
    n=$((n + 1))
    "$OLD" render "$@" -o "$out/$name.old.exr" --quiet >"$out/$name.old.log" 2>&1
    local ro=$?
    "$NEW" render "$@" -o "$out/$name.new.exr" --quiet >"$out/$name.new.log" 2>&1
    local rn=$?
    if [ $ro != 0 ] || [ $rn != 0 ]; then
        if [ $ro = $rn ]; then
            refused=$((refused + 1))
        else
            differ=$((differ + 1))
            echo "DIFFERS: $name: exit $ro (old) vs $rn (new): $(tail -n 1 "$out/$name.new.log")"
        fi
        return
    fi
    if "$NEW" diff "$out/$name.old.exr" "$out/$name.new.exr" --max-error 0 >"$out/$name.diff" 2>&1; then
        same=$((same + 1))
        rm -f "$out/$name.old.exr" "$out/$name.new.exr"
    else
        differ=$((differ + 1))
        echo "DIFFERS: $name: $(grep -E '^(rmse|max_err)' "$out/$name.diff" | tr '\n' ' ')"
    fi
}
for s in "${scenes[@]}"; do
    name=$(echo "${s#$A/}" | tr '/' '_')
    compare "$name" "$s" --size 48x48 --spp 4
done
for m in path phong gouraud flat normal albedo depth cost; do
    compare "cornell-$m" scenes/cornell.gltf --size 48x48 --spp 4 --mode $m --aov normal,albedo,depth,variance
done
echo "same_images: $n renders: $same identical, $refused refused by both, $differ differ"
[ $differ = 0 ]
