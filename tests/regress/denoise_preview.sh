#!/usr/bin/env bash
# denoise_preview.sh: `gonio preview`'s denoised view in a virtual X display (as preview.sh):
# --denoise shows, once the samples have settled, what `render --denoise` writes for the
# same samples (within one 8-bit level) and says so in the title; N switches to the noisy
# view (what render without --denoise writes) and back; N in a render started without the
# guides restarts it with them; without the library --denoise is an error (exit 1).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=scenes/cornell.gltf

if [ "${GONIO_PREVIEW_XVFB:-}" != 1 ]; then
    for t in xvfb-run xauth xdotool import compare identify; do
        command -v $t >/dev/null || skip_all "$t is missing (make test-deps installs it)"
    done
    GONIO_PREVIEW_XVFB=1 exec xvfb-run -a -s "-screen 0 320x240x24" "$0" "$@"
fi

check_fails "preview --denoise without the library: exit 1" 1 \
    env GONIO_OIDN_LIB="$tmp/none.so" "$G" preview $C --denoise --frames 1
check "... naming what is missing" sh -c "grep -q GONIO_OIDN_LIB '$tmp/last' && grep -q 'make denoiser' '$tmp/last'"
lib=$(dirname "$G")/../oidn/lib/libOpenImageDenoise.so.2
if [ ! -e "$lib" ] && [ -z "${GONIO_OIDN_LIB:-}" ]; then
    if [ "${GONIO_REQUIRE_DENOISER:-}" = 1 ]; then
        fail "Open Image Denoise is required here (GONIO_REQUIRE_DENOISER=1) but $lib is absent"
        finish
        exit 1
    fi
    [ "$n_fail" = 0 ] || { finish; exit 1; }
    skip_all "no Open Image Denoise at $lib (make denoiser fetches it): the denoised view was not tried"
fi

# same_image A.png B.png: as preview.sh's (one 8-bit level, at most 1% of the pixels).
same_image() {
    local size e n
    size=$(identify -format %wx%h "$1")
    [ "$size" = "$(identify -format %wx%h "$2")" ] || return 1
    e=$(compare -metric PAE "$1" "$2" null: 2>&1 | sed -n 's/.*(\(.*\)).*/\1/p')
    n=$(compare -metric AE "$1" "$2" null: 2>&1)
    echo "$1 vs $2: peak $e, $n pixel(s) differ"
    awk -v e="$e" -v n="$n" -v s="$size" 'BEGIN { split(s, d, "x")
        exit !(e != "" && e <= 1.5 / 255 && n + 0 <= d[1] * d[2] / 100) }'
}
differs() { ! same_image "$@"; }
V="--size 160x120 --spp 16"
check "render --denoise, 16 spp" "$G" render $C --png "$tmp/denoised.png" $V --denoise --quiet
check "render, 16 spp" "$G" render $C --png "$tmp/noisy.png" $V --quiet
check "... the two differ" differs "$tmp/denoised.png" "$tmp/noisy.png"

timeout 120 "$G" preview $C $V --denoise --frames 4000 >"$tmp/pv.out" 2>"$tmp/pv.err" &
pid=$!
wid=$(timeout 30 xdotool search --sync --name '^gonio preview')
wait_title() { # wait_title PATTERN: up to 60 s for the window title to match
    for _ in $(seq 600); do
        xdotool getwindowname "$wid" 2>/dev/null | grep -Eq "$1" && return 0
        sleep 0.1
    done
    echo "title: $(xdotool getwindowname "$wid" 2>&1)"; return 1
}
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
check "Esc" xdotool key Escape
wait $pid
rc=$?
[ $rc = 0 ] && pass || { fail "preview exit status $rc"; cat "$tmp/pv.err"; }
check "no validation messages" sh -c "! grep -q validation '$tmp/pv.err'"

# N in a preview started without --denoise: the render restarts with the guides.
timeout 120 "$G" preview $C $V --frames 4000 >"$tmp/pv2.out" 2>"$tmp/pv2.err" &
pid=$!
wid=$(timeout 30 xdotool search --sync --name '^gonio preview')
check "a second window opens" test -n "$wid"
check "title: 16 spp, no denoising" wait_title '\| 16 spp \| [^|]*\| [^|]*\| EV [^|]*$'
check "focus" xdotool windowfocus --sync "$wid"
check "key n" xdotool key n
check "title: denoised at 16 spp" wait_title 'denoised at 16 spp'
check "import the window" import -window "$wid" "$tmp/win-n.png"
check "it shows what render --denoise writes" same_image "$tmp/win-n.png" "$tmp/denoised.png"
check "Esc" xdotool key Escape
wait $pid
rc=$?
[ $rc = 0 ] && pass || { fail "preview exit status $rc"; cat "$tmp/pv2.err"; }
kill $pid 2>/dev/null

finish
