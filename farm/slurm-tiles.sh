#!/usr/bin/env bash
# A Slurm job array: one task per (tile, seed) of one still, then a merge that waits for
# the whole array. Submit from the repository (or set GONIO) with:
#   farm/slurm-tiles.sh SCENE.gltf OUT.exr [TILES_X TILES_Y SEEDS SPP WxH]
# Each task renders tile (i, j) with seed s; `gonio merge` assembles the tiles and combines
# the seeds into exactly the image of one render of SEEDS x SPP samples.
set -euo pipefail
scene=$1 out=$2 tx=${3:-3} ty=${4:-3} seeds=${5:-2} spp=${6:-64} size=${7:-512x512}
gonio=${GONIO:-$(command -v gonio || echo build/gonio)}
parts=${PARTS:-$(dirname "$out")/parts}
mkdir -p "$parts"
w=${size%x*} h=${size#*x} n=$((tx * ty * seeds))
# Task k: seed k / (tx ty), tile (k % tx, k / tx % ty); integer pixel bounds.
task=$(cat <<TASK
k=\$SLURM_ARRAY_TASK_ID; s=\$((k / ($tx * $ty))); i=\$((k % $tx)); j=\$((k / $tx % $ty))
x0=\$((i * $w / $tx)); x1=\$(((i + 1) * $w / $tx)); y0=\$((j * $h / $ty)); y1=\$(((j + 1) * $h / $ty))
exec "$gonio" render "$scene" --size $size --spp $spp --seed \$s --crop \$x0,\$y0,\$x1,\$y1 \
    --quiet -o "$parts/tile_\${s}_\${i}_\${j}.exr"
TASK
)
array=$(sbatch --parsable --job-name=gonio-tiles --array=0-$((n - 1)) ${SBATCH_ARGS:-} \
    --output="$parts/slurm-%A_%a.log" --wrap="$task")
merge=$(sbatch --parsable --job-name=gonio-merge --dependency=afterok:$array ${SBATCH_ARGS:-} \
    --output="$parts/slurm-%j.log" --wrap="\"$gonio\" merge \"$parts\"/tile_*.exr -o \"$out\"")
echo "array $array merge $merge"
