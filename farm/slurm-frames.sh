#!/usr/bin/env bash
# A Slurm job array over the frames of a glTF animation, one task a frame:
#   farm/slurm-frames.sh SCENE.gltf OUTDIR FIRST LAST [FPS SPP WxH]
# Frame N goes to OUTDIR/frame_NNNN.exr (gonio render --frame N --fps FPS).
set -euo pipefail
scene=$1 dir=$2 first=$3 last=$4 fps=${5:-24} spp=${6:-64} size=${7:-640x360}
gonio=${GONIO:-$(command -v gonio || echo build/gonio)}
mkdir -p "$dir"
sbatch --parsable --job-name=gonio-frames --array=$first-$last ${SBATCH_ARGS:-} \
    --output="$dir/slurm-%A_%a.log" \
    --wrap="f=\$SLURM_ARRAY_TASK_ID; exec \"$gonio\" render \"$scene\" --frame \$f --fps $fps --spp $spp \
            --size $size --quiet -o \"$dir/\$(printf frame_%04d.exr \$f)\""
