#!/usr/bin/env bash
# denoise_preview.sh: `gonio preview`'s denoised view in a virtual X display (as preview.sh):
# --denoise shows, once the samples have settled, what `render --denoise` writes for the
# same samples (within one 8-bit level) and says so in the title; N switches to the noisy
# view (what render without --denoise writes) and back; N in a render started without the
# guides restarts it with them; without the library --denoise is an error (exit 1).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=scenes/cornell.gltf

in_xvfb "$@"

check_fails "preview --denoise without the library: exit 1" 1 \
    env GONIO_OIDN_LIB="$tmp/none.so" "$G" preview $C --denoise --frames 1
check "... naming what is missing" sh -c "grep -q GONIO_OIDN_LIB '$tmp/last' && grep -q 'make denoiser' '$tmp/last'"
need_denoiser "the denoised view was not tried"

# (same_image A.png B.png, differs: lib.sh's, one 8-bit level at the most)
title_wait_s=60 # wait_title's limit (lib.sh): the denoised view comes once the samples settle
V="--size 160x120 --spp 16"
check "render --denoise, 16 spp" "$G" render $C --png "$tmp/denoised.png" $V --denoise --quiet
check "render, 16 spp" "$G" render $C --png "$tmp/noisy.png" $V --quiet
check "... the two differ" differs "$tmp/denoised.png" "$tmp/noisy.png"

preview_open "$tmp/pv" $C $V --denoise --frames 4000
check "the window opens" test -n "$wid"
check "title: denoised at 16 spp, with its time" wait_title '\| 16 spp \|.*\| denoised at 16 spp \([0-9.]+ s\)$'
check "import the window" import -window "$wid" "$tmp/win-denoised.png"
check "it shows what render --denoise writes" same_image "$tmp/win-denoised.png" "$tmp/denoised.png"
check "focus" xdotool windowfocus --sync "$wid"
check "key n" xdotool key n
check "title: no longer denoised" wait_title '\| 16 spp \| [^|]*\| [^|]*\| EV [^|]*$'
check "import the window (noisy)" import -window "$wid" "$tmp/win-noisy.png"
check "it shows what render writes" same_image "$tmp/win-noisy.png" "$tmp/noisy.png"
check "key n again" xdotool key n
check "title: denoised at 16 spp again (no new render)" wait_title 'denoised at 16 spp'
check "import the window (denoised again)" import -window "$wid" "$tmp/win-denoised2.png"
check "... the denoised image" same_image "$tmp/win-denoised2.png" "$tmp/denoised.png"
preview_close "$tmp/pv"
check "no validation messages" sh -c "! grep -q validation '$tmp/pv.err'"

# N in a preview started without --denoise: the render restarts with the guides.
preview_open "$tmp/pv2" $C $V --frames 4000
check "a second window opens" test -n "$wid"
check "title: 16 spp, no denoising" wait_title '\| 16 spp \| [^|]*\| [^|]*\| EV [^|]*$'
check "focus" xdotool windowfocus --sync "$wid"
check "key n" xdotool key n
check "title: denoised at 16 spp" wait_title 'denoised at 16 spp'
check "import the window" import -window "$wid" "$tmp/win-n.png"
check "it shows what render --denoise writes" same_image "$tmp/win-n.png" "$tmp/denoised.png"
preview_close "$tmp/pv2"
kill $pid 2>/dev/null

finish
