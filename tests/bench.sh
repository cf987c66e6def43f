#!/usr/bin/env bash
# bench.sh GONIO: make bench. BVH build rate, ray throughput and time to first pixel on the
# Cornell box, the largest glTF sample model in ../shared/assets (when present), and a
# generated mesh of about 250k triangles.
set -u
G=${1:-build/gonio}
assets=${GONIO_ASSETS:-../shared/assets}/gltf
echo "== scenes/cornell.gltf"
"$G" bench scenes/cornell.gltf || exit 1
if [ -d "$assets" ]; then
    best= most=0
    for f in "$assets"/*/glTF/*.gltf; do
        n=$("$G" info "$f" 2>/dev/null | awk '$1 == "triangles" {print $2}')
        if [ -n "$n" ] && [ "$n" -gt "$most" ]; then most=$n best=$f; fi
    done
    echo "== $best (the largest sample model: $most triangles)"
    "$G" bench "$best" || exit 1
else
    echo "== $assets is absent: skipping the sample-model benchmark"
fi
echo "== generated mesh, 250k triangles"
"$G" bench --generate 250000 || exit 1
