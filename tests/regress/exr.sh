#!/usr/bin/env bash
# exr.sh: EXRs gonio writes are the files OpenEXR's C++ library (exrmaketiled, exrmakepreview
# of the openexr tools) writes and reads, and the other way round; B44/B44A in particular,
# which pack half channels and store float ones as they are.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v exrmaketiled >/dev/null && command -v exrmakepreview >/dev/null ||
    skip_all "exrmaketiled/exrmakepreview (Debian: openexr) are needed"
C=scenes/cornell.gltf
R="--size 45x37 --spp 2 --aov normal,depth --quiet"
# The renders run in one batch (lib.sh: queue); the checks read each line's status.
queue f render $C -o "$tmp/f.exr" $R --compression none
queue h render $C -o "$tmp/h.exr" $R --compression none --half
for comp in b44 b44a; do
    queue "f-$comp" render $C -o "$tmp/f-$comp.exr" $R --compression $comp
    queue "h-$comp" render $C -o "$tmp/h-$comp.exr" $R --compression $comp --half
done
run_queue
check_queued "a float render" 0 f
check_queued "a half render" 0 h
for comp in b44 b44a; do
    # Float channels are stored whole: every one of these reads back exactly.
    check_queued "$comp float: gonio writes it" 0 "f-$comp"
    check "$comp float: gonio reads its own file exactly" "$G" diff "$tmp/f-$comp.exr" "$tmp/f.exr" --max-error 0 --quiet
    check "$comp float: OpenEXR's library reads gonio's file" exrmaketiled -z none "$tmp/f-$comp.exr" "$tmp/f-$comp-lib.exr"
    check "... exactly" "$G" diff "$tmp/f-$comp-lib.exr" "$tmp/f.exr" --max-error 0 --quiet
    check "$comp float: the library writes it tiled" exrmaketiled -z $comp -t 16 8 "$tmp/f.exr" "$tmp/f-$comp-tiled.exr"
    check "... and gonio reads it exactly" "$G" diff "$tmp/f-$comp-tiled.exr" "$tmp/f.exr" --max-error 0 --quiet
    check "$comp float: the library writes it in scanlines" exrmakepreview "$tmp/f-$comp.exr" "$tmp/f-$comp-lines.exr"
    check "... and gonio reads it exactly" "$G" diff "$tmp/f-$comp-lines.exr" "$tmp/f.exr" --max-error 0 --quiet
    # Half channels are packed (lossy): gonio and the library decode the same values.
    check_queued "$comp half: gonio writes it" 0 "h-$comp"
    check "$comp half: the library decodes gonio's file" exrmaketiled -z none "$tmp/h-$comp.exr" "$tmp/h-$comp-lib.exr"
    check "... to the values gonio decodes" "$G" diff "$tmp/h-$comp.exr" "$tmp/h-$comp-lib.exr" --max-error 0 --quiet
    check "... within B44's loss of the render" "$G" diff "$tmp/h-$comp.exr" "$tmp/h.exr" --max-rmse 0.05 --quiet
    check "$comp half: the library writes it tiled" exrmaketiled -z $comp -t 7 5 "$tmp/h.exr" "$tmp/h-$comp-tiled.exr"
    check "... and decodes it" exrmaketiled -z none "$tmp/h-$comp-tiled.exr" "$tmp/h-$comp-tiled-lib.exr"
    check "... to the values gonio decodes" "$G" diff "$tmp/h-$comp-tiled.exr" "$tmp/h-$comp-tiled-lib.exr" --max-error 0 --quiet
done
finish
