#!/usr/bin/env bash
# quality.sh GONIO TESTTOOL [OUT]: the denoiser's figures of docs/performance.md (make
# bench-denoise). For the Cornell box, the Stanford bunny (tests/denoise/bunny.py) and
# DamagedHelmet under a constant environment of 1 (the peer bench's view), at SIZE
# (default 256x256): a reference of REF_SPP spp (default 1024, seed 1, with its variance),
# then renders of 16 and 64 spp (seed 0) with --denoise. Prints for each the RMSE of the
# noisy and the denoised image against the reference (linear RGB; the same less the
# reference's own noise; clamped to [0, 1] as the default PNG shows it), their ratio and the
# denoised mean's relative difference from the reference's (testtool errors). Leaves in OUT
# (default build/denoise) the EXRs, the PNGs, NAME-SPP.png: noisy | denoised | reference, and
# denoise.jpg, their 16 spp rows (docs/img/denoise.jpg).
# Then `gonio bench --paths --denoise` on each (its camera, or the framing one): the time to
# an RMSE of 0.05 and 0.02 with and without the denoiser (the equal-quality speed-up).
# References are kept and reused while OUT holds them (delete them after changing gonio).
# BENCH=0 leaves the benches out.
set -eu
G=${1:?usage: quality.sh GONIO TESTTOOL [OUT]}
T=${2:?usage: quality.sh GONIO TESTTOOL [OUT]}
OUT=${3:-build/denoise}
SIZE=${SIZE:-256x256}
REF_SPP=${REF_SPP:-1024}
ASSETS=${GONIO_ASSETS:-$(dirname "$0")/../../../shared/assets}
mkdir -p "$OUT"

# name|file|render options|bench options (bench takes the file's camera or frames the scene)
scenes=("cornell|scenes/cornell.gltf||")
if [ -f "$ASSETS/mesh/stanford-bunny.obj" ]; then
    python3 "$(dirname "$0")/bunny.py" "$ASSETS/mesh/stanford-bunny.obj" "$OUT/bunny.gltf"
    scenes+=("bunny|$OUT/bunny.gltf||")
else
    echo "quality: the bunny skipped: $ASSETS/mesh/stanford-bunny.obj is absent"
fi
helmet=$ASSETS/gltf/DamagedHelmet/glTF/DamagedHelmet.gltf
if [ -f "$helmet" ]; then
    scenes+=("helmet|$helmet|--env 1 --look-at 1.2,0.6,2.6,0,0,0 --fov 40|--env 1")
else
    echo "quality: DamagedHelmet skipped: $helmet is absent"
fi

echo "denoise quality: $SIZE, reference $REF_SPP spp; $("$G" --version); $(uptime | sed 's/.*load/load/')"
row() { printf "%-7s %4s | %-8s %-8s %-5s | %-8s %-8s %-5s | %-9s %-9s | %s\n" "$@"; }
row scene spp noisy denoised ratio noisy-d denois-d ratio mean-noisy mean-dn "denoise s"
for s in "${scenes[@]}"; do
    IFS='|' read -r name file opts _ <<<"$s"
    ref=$OUT/$name-ref.exr
    if [ ! -f "$ref" ]; then
        # shellcheck disable=SC2086 # opts holds several options
        "$G" render "$file" $opts --size "$SIZE" --spp "$REF_SPP" --seed 1 --aov variance -o "$ref" \
            --quiet
    fi
    [ -f "$OUT/$name-ref.png" ] || "$T" png "$ref" "$OUT/$name-ref.png"

    for spp in 16 64; do
        # shellcheck disable=SC2086
        "$G" render "$file" $opts --size "$SIZE" --spp "$spp" -o "$OUT/$name-$spp-noisy.exr" \
            --png "$OUT/$name-$spp-noisy.png" --quiet
        # shellcheck disable=SC2086
        "$G" render "$file" $opts --size "$SIZE" --spp "$spp" --denoise -o "$OUT/$name-$spp.exr" \
            --png "$OUT/$name-$spp-denoised.png" 2>"$OUT/$name-$spp.log"
        read -r _ _ _ n _ _ _ nd _ nm _ _ < <("$T" errors "$OUT/$name-$spp-noisy.exr" "$ref")
        read -r _ _ _ d _ _ _ dd _ dm _ _ < <("$T" errors "$OUT/$name-$spp.exr" "$ref")
        secs=$(sed -n 's/.*denoised in \([0-9.]*\) s.*/\1/p' "$OUT/$name-$spp.log")
        row "$name" "$spp" "$n" "$d" "$(awk -v a="$n" -v b="$d" 'BEGIN { printf "%.2f", b / a }')" "$nd" "$dd" \
            "$(awk -v a="$nd" -v b="$dd" 'BEGIN { printf "%.2f", b / a }')" "$nm" "$dm" "$secs"
        convert "$OUT/$name-$spp-noisy.png" "$OUT/$name-$spp-denoised.png" "$OUT/$name-ref.png" +append \
            "$OUT/$name-$spp.png"
    done
done
# docs/img/denoise.jpg: the 16 spp rows, one a scene.
rows=()
for s in "${scenes[@]}"; do rows+=("$OUT/${s%%|*}-16.png"); done
convert "${rows[@]}" -append -quality 85 "$OUT/denoise.jpg"
echo "noisy, denoised: the RMSE against the reference in linear RGB less the reference's own"
echo "noise; -d: of both clamped to [0, 1] (the default PNG before its sRGB curve), less the"
echo "noise of the reference's values below 1; ratio: denoised / noisy; mean: the image's mean"
echo "over the reference's - 1; denoise s: the denoise's time (render --denoise's summary)"

[ "${BENCH:-1}" = 0 ] && exit 0 # BENCH=0: the table and pictures only
for s in "${scenes[@]}"; do
    IFS='|' read -r name file _ bopts <<<"$s"
    # A 2048 spp reference: the default 512's own noise (0.011-0.013 in the Cornell box and
    # the bunny) is too near the 0.02 threshold for the crossing to be read.
    echo "== gonio bench $name --paths --denoise --size 256x256 --reference 128x128:2048 $bopts"
    # shellcheck disable=SC2086
    "$G" bench "$file" --paths --denoise --size 256x256 --reference 128x128:2048 $bopts |
        grep -E "^(paths|reference|rmse|denoised|denoise speed)"
done
