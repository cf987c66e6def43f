#!/usr/bin/env bash
# bench.sh GONIO: make bench. BVH build rate, ray throughput and time to first pixel on the
# Cornell box, the largest glTF sample model in $GONIO_ASSETS (when present), and a
# generated mesh of about 250k triangles; then the path tracer (bench --paths: paths/s at
# 256x256, first pixel, time to an RMSE) on the Cornell box and a textured sample model.
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
echo "== path tracing: scenes/cornell.gltf, 256x256"
"$G" bench scenes/cornell.gltf --paths --size 256x256 || exit 1
helmet=$assets/DamagedHelmet/glTF/DamagedHelmet.gltf
if [ -f "$helmet" ]; then
    echo "== path tracing: $helmet (textured), 256x256, white environment"
    "$G" bench "$helmet" --paths --size 256x256 --env 1 || exit 1
else
    echo "== $helmet is absent: skipping the textured path-tracing benchmark"
fi
