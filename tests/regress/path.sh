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

# Ctrl-C: the render stops after the current pass and writes what it has.
"$G" render $C -o "$tmp/int.exr" --time 60 --size 32x32 --quiet &
pid=$!
sleep 3
kill -INT $pid
wait $pid
check "an interrupted render exits 0" test $? = 0
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
