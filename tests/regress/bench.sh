#!/usr/bin/env bash
# bench.sh: `gonio bench --generate` and `gonio bench --paths` run and prints every figure (first pixel, paths/s, the
# reference and both RMSE thresholds) on the Cornell box at a tiny size, so the command
# behind docs/performance.md's figures cannot rot.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
check "bench --paths on the Cornell box" "$G" bench scenes/cornell.gltf --paths --size 16x16 \
    --seconds 0.2 --reference 16x16:32
cp "$tmp/out" "$tmp/bench.txt"
for line in "first pixel .* s after start \\(path" "paths .* M paths/s" "reference .*32 spp" \
    "rmse < 0.05 " "rmse < 0.02 " "bvh build"; do
    check "prints '$line'" grep -Eq "^$line" "$tmp/bench.txt"
done
# A generated mesh has no lights at all: the ray bench must still run (it once passed a null
# light table to memcpy, which only the sanitizer build noticed).
check "bench --generate runs" "$G" bench --generate 3000 --size 32x32
cp "$tmp/out" "$tmp/gen.txt"
for line in "primary rays .* Mrays/s" "diffuse rays .* Mrays/s" "bvh build .* M triangles/s"; do
    check "prints '$line'" grep -Eq "^$line" "$tmp/gen.txt"
done
check_fails "a bad --reference is a usage error" 2 "$G" bench --paths --reference 16x16
finish
