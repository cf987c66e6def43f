#!/usr/bin/env bash
# preview.sh: `gonio preview` in a virtual X display (xvfb-run) on lavapipe, validation on:
# its --screenshot, the X server's own capture of the window, and the files of the P key
# equal `gonio render` of the same view and sample count (the same kernels and samples, so
# within one 8-bit level); keys typed with xdotool switch modes; a resize restarts at the
# new size; without a display the error points to `gonio render` and xvfb-run.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=scenes/cornell.gltf

in_xvfb "$@" # the rest runs inside one virtual display (lib.sh)

check_fails "no display: exit 1" 1 env -u DISPLAY -u WAYLAND_DISPLAY "$G" preview $C
check "no display: the message points to gonio render and xvfb-run" \
    sh -c "grep -q 'gonio render' '$tmp/last' && grep -q xvfb-run '$tmp/last'"
check_fails "bad --mode" 2 "$G" preview $C --mode bogus
check_fails "--screenshot needs a .png name" 2 "$G" preview $C --screenshot "$tmp/shot.exr"
check_fails "no scene" 2 "$G" preview
check_fails "missing scene" 1 "$G" preview "$tmp/nope.gltf" --frames 1
check "missing scene: message names the file" grep -q nope.gltf "$tmp/last"
check "preview --help lists the keys" sh -c "'$G' preview --help | grep -q Esc"

# (same_image A.png B.png, differs: lib.sh's, one 8-bit level at the most)
ref() { # ref NAME MODE WxH [render options]: the reference render, EXR and PNG
    local n=$1 m=$2 s=$3; shift 3
    check "render $n" "$G" render $C -o "$tmp/$n.exr" --png "$tmp/$n.png" --mode $m --size $s \
        --spp 4 --quiet "$@"
}
ref phong phong 160x120
ref phong-aces phong 160x120 --tonemap aces --exposure 1.5
ref albedo albedo 160x120
ref albedo-big albedo 200x150
check "render phong, 1 spp" "$G" render $C --png "$tmp/phong-1.png" --size 160x120 --spp 1 --quiet

# ---- scripted: N frames, then the screenshot ---------------------------------------------
"$G" preview $C --size 32x24 --spp 1 --frames 2 --screenshot "$tmp/default.png" 2>"$tmp/default.err"
check "the preview's default mode is the path tracer" grep -q 'frame(s), path, ' "$tmp/default.err"
check "preview 8 frames at 4 spp" "$G" preview $C --mode phong --size 160x120 --spp 4 --frames 8 \
    --screenshot "$tmp/shot.png"
check "screenshot equals gonio render" same_image "$tmp/shot.png" "$tmp/phong.png"
check "...and the comparison can fail: 1 spp differs" differs "$tmp/shot.png" "$tmp/phong-1.png"
check "preview with aces and exposure" "$G" preview $C --mode phong --size 160x120 --spp 4 --frames 8 \
    --tonemap aces --exposure 1.5 --screenshot "$tmp/shot-aces.png"
check "aces screenshot equals gonio render" same_image "$tmp/shot-aces.png" "$tmp/phong-aces.png"

# ---- interactive: X captures while it runs, keys, resize, P, Esc ------------------------
preview_open "$tmp/pv" $C --mode phong --size 160x120 --spp 4 --frames 2400 --prefix "$tmp/saved" \
    --screenshot "$tmp/end.png"
colours() { identify -format %k "$1"; }
check "the window opens" test -n "$wid"
check "title: phong, size, 4 spp" wait_title '^gonio preview: phong \| 160x120 \| 4 spp \| [0-9.]+ Mpaths/s \| [0-9.]+ ms'
check "import the root window" import -window root "$tmp/root.png"
check "the screen is not blank" test "$(colours "$tmp/root.png")" -gt 50
check "import the preview window" import -window "$wid" "$tmp/win-phong.png"
check "the window shows the render" same_image "$tmp/win-phong.png" "$tmp/phong.png"
check "focus" xdotool windowfocus --sync "$wid"
check "key 6" xdotool key 6
check "title: albedo" wait_title '^gonio preview: albedo \| 160x120 \| 4 spp'
check "import the window (albedo)" import -window "$wid" "$tmp/win-albedo.png"
check "the window shows the albedo render" same_image "$tmp/win-albedo.png" "$tmp/albedo.png"
# Mode 1 (path) switches, or says it is not available and stays.
check "key 1" xdotool key 1
check "key 1: path" sh -c "for i in \$(seq 300); do xdotool getwindowname $wid | grep -q ': path' \
    && exit 0; sleep 0.1; done; exit 1"
check "key 6 again" xdotool key 6
check "hide and show" sh -c "xdotool windowunmap --sync $wid && sleep 0.3 && xdotool windowmap --sync $wid"
check "resize" xdotool windowsize --sync "$wid" 200 150
check "title: restarted at the new size" wait_title '^gonio preview: albedo \| 200x150 \| 4 spp'
check "key p" xdotool key p
check "P names its files" sh -c "for i in \$(seq 100); do grep -q 'wrote .*saved-001.exr and .*saved-001.png (albedo, 4 spp)' \
    '$tmp/pv.out' && exit 0; sleep 0.1; done; exit 1"
check "P's EXR equals gonio render's" "$G" diff "$tmp/saved-001.exr" "$tmp/albedo-big.exr" --max-error 1e-6 --quiet
check "P's PNG equals gonio render's" same_image "$tmp/saved-001.png" "$tmp/albedo-big.png"
# The saved EXR carries the view: render --camera FILE.exr renders the same view.
check "render from the view P saved" "$G" render $C --camera "$tmp/saved-001.exr" -o "$tmp/from-view.exr" \
    --mode albedo --size 200x150 --spp 4 --quiet
check "... gives P's pixels" "$G" diff "$tmp/from-view.exr" "$tmp/saved-001.exr" --max-error 1e-6 --quiet
preview_close "$tmp/pv"
check "the quit screenshot shows the last view" same_image "$tmp/end.png" "$tmp/albedo-big.png"
check "no validation messages" sh -c "! grep -q validation '$tmp/pv.err'"
kill $pid 2>/dev/null

finish
