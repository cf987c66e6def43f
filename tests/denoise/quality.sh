#!/usr/bin/env bash
# quality.sh GONIO TESTTOOL [OUT]: the denoiser's figures of docs/performance.md (make
# bench-denoise). For the Cornell box, the Stanford bunny (tests/denoise/bunny.py) and
# DamagedHelmet under a constant environment of 1 (the peer bench's view), at SIZE
# (default 256x256): a reference of REF_SPP spp (default 1024, seed 1, with its variance),
# then renders of 16 and 64 spp (seed 0) with --denoise. Prints for each the RMSE of the
# noisy and the denoised image against the reference (linear RGB; the same less the
# reference's own noise; clamped to [0, 1] as the default PNG shows it), their ratio and the
# denoised mean's relative difference from the reference's (testtool errors). Leaves in OUT
# (default build/denoise) the EXRs, the PNGs and NAME-SPP.png: noisy | denoised | reference.
# References are kept and reused while OUT holds them (delete them after changing gonio).
set -eu
G=${1:?usage: quality.sh GONIO TESTTOOL [OUT]}
T=${2:?usage: quality.sh GONIO TESTTOOL [OUT]}
OUT=${3:-build/denoise}
SIZE=${SIZE:-256x256}
REF_SPP=${REF_SPP:-1024}
ASSETS=${GONIO_ASSETS:-$(dirname "$0")/../../../shared/assets}
mkdir -p "$OUT"

scenes=("cornell|scenes/cornell.gltf|")
if [ -f "$ASSETS/mesh/stanford-bunny.obj" ]; then
    python3 "$(dirname "$0")/bunny.py" "$ASSETS/mesh/stanford-bunny.obj" "$OUT/bunny.gltf"
    scenes+=("bunny|$OUT/bunny.gltf|")
else
    echo "quality: the bunny skipped: $ASSETS/mesh/stanford-bunny.obj is absent"
fi
helmet=$ASSETS/gltf/DamagedHelmet/glTF/DamagedHelmet.gltf
if [ -f "$helmet" ]; then
    scenes+=("helmet|$helmet|--env 1 --look-at 1.2,0.6,2.6,0,0,0 --fov 40")
else
    echo "quality: DamagedHelmet skipped: $helmet is absent"
fi

echo "denoise quality: $SIZE, reference $REF_SPP spp; $("$G" --version); $(uptime | sed 's/.*load/load/')"
printf "%-8s %4s  %-9s %-9s %-9s %-9s %-7s %-9s %-9s %-7s %-8s %-6s\n" scene spp noisy denoised \
    noisy-c denoised-c ratio-c noisy-d denoised-d ratio-d mean "time"
for s in "${scenes[@]}"; do
    IFS='|' read -r name file opts <<<"$s"
    ref=$OUT/$name-ref.exr
    if [ ! -f "$ref" ]; then
        # shellcheck disable=SC2086 # opts holds several options
        "$G" render "$file" $opts --size "$SIZE" --spp "$REF_SPP" --seed 1 --aov variance -o "$ref" \
            --png "$OUT/$name-ref.png" --quiet
    fi
    for spp in 16 64; do
        # shellcheck disable=SC2086
        "$G" render "$file" $opts --size "$SIZE" --spp "$spp" -o "$OUT/$name-$spp-noisy.exr" \
            --png "$OUT/$name-$spp-noisy.png" --quiet
        # shellcheck disable=SC2086
        "$G" render "$file" $opts --size "$SIZE" --spp "$spp" --denoise -o "$OUT/$name-$spp.exr" \
            --png "$OUT/$name-$spp-denoised.png" 2>"$OUT/$name-$spp.log"
        read -r _ n _ nc _ nd _ _ _ _ < <("$T" errors "$OUT/$name-$spp-noisy.exr" "$ref")
        read -r _ d _ dc _ dd _ mean _ _ < <("$T" errors "$OUT/$name-$spp.exr" "$ref")
        secs=$(sed -n 's/.*denoised in \([0-9.]*\) s.*/\1/p' "$OUT/$name-$spp.log")
        printf "%-8s %4s  %-9s %-9s %-9s %-9s %-7s %-9s %-9s %-7s %-8s %-6s\n" "$name" "$spp" "$n" "$d" "$nc" "$dc" \
            "$(awk -v a="$nc" -v b="$dc" 'BEGIN { printf "%.2f", b / a }')" "$nd" "$dd" \
            "$(awk -v a="$nd" -v b="$dd" 'BEGIN { printf "%.2f", b / a }')" "$mean" "$secs"
        convert "$OUT/$name-$spp-noisy.png" "$OUT/$name-$spp-denoised.png" "$OUT/$name-ref.png" +append \
            "$OUT/$name-$spp.png"
    done
done
echo "columns: RMSE of the noisy and denoised images against the reference (linear RGB); -c: the"
echo "same less the reference's own noise; -d: both clamped to [0, 1]; ratio: denoised / noisy;"
echo "mean: the denoised image's mean / the reference's - 1; time: the denoise's seconds"
