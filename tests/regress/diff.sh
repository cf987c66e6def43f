#!/usr/bin/env bash
# diff.sh: `gonio diff` end to end on EXRs from other writers (ImageMagick, OpenEXR's
# exrmaketiled): metrics against hand-computed values, thresholds, exit status 0/1/2.
. "$(dirname "$0")/../lib.sh"
G=$GONIO

# run STATUS DESCRIPTION ARGS...: gonio diff ARGS must exit STATUS; stdout in $tmp/d.out,
# stderr in $tmp/d.err.
run() {
    local want=$1 what=$2 got=0
    shift 2
    "$G" diff "$@" >"$tmp/d.out" 2>"$tmp/d.err" || got=$?
    if [ "$got" = "$want" ]; then pass; else fail "$what (exit $got, expected $want)"; sed 's/^/    /' "$tmp/d.err"; fi
}
# near METRIC WANT: the printed value is within 1e-4 of WANT (or equal, for inf).
near() {
    local v
    v=$(awk -v k="$1" '$1 == k { print $2 }' "$tmp/d.out")
    if awk -v v="$v" -v w="$2" 'BEGIN { exit !(v == w || (v - w < 1e-4 && w - v < 1e-4)) }'; then pass
    else fail "$1 = '$v', expected $2"; fi
}
err_has() { if grep -qF -- "$1" "$tmp/d.err"; then pass; else fail "stderr lacks '$1': $(cat "$tmp/d.err")"; fi; }

if ! convert -list format 2>/dev/null | grep -q 'EXR.*rw'; then
    skip_all "ImageMagick cannot write EXR"
fi

# 2x2 RGB (half) images: black, and black with one red pixel (0 and 1 are the same in sRGB
# and linear, so no colour conversion can change them).
convert -size 2x2 xc:black -define exr:color-type=RGB "$tmp/black.exr"
convert -size 2x2 xc:black -fill red -draw 'point 0,0' -define exr:color-type=RGB "$tmp/dot.exr"
convert -size 4x2 xc:black -define exr:color-type=RGB "$tmp/wide.exr"
echo "not an image" >"$tmp/text.exr"

run 0 "identical images" "$tmp/dot.exr" "$tmp/dot.exr"
near rmse 0; near max_err 0; near rel_bias 0
check "psnr of identical images is inf" grep -q '^psnr inf dB$' "$tmp/d.out"

# A = black, B = dot: of 12 values one (R of pixel 0) differs, by 1.
run 0 "black against dot" "$tmp/black.exr" "$tmp/dot.exr"
near rmse 0.288675 # sqrt(1/12)
near mae 0.0833333 # 1/12
near max_err 1
near rel_bias -1 # (0 - 1/12) / (1/12)
near psnr 10.79  # 20 log10(1 / sqrt(1/12)), peak = max |B| = 1
run 0 "dot against black" "$tmp/dot.exr" "$tmp/black.exr"
near psnr 10.79 # B all zero: peak 1
near rel_bias inf

# A tiled copy made by OpenEXR's own tool reads back identical.
check "exrmaketiled" exrmaketiled -t 1 1 "$tmp/dot.exr" "$tmp/dot-tiled.exr"
run 0 "tiled copy" "$tmp/dot-tiled.exr" "$tmp/dot.exr" --max-error 0

# Thresholds.
run 0 "within limits" "$tmp/black.exr" "$tmp/dot.exr" --max-rmse 0.3 --max-error 1 --max-rel-bias 1
run 1 "rmse over the limit" "$tmp/black.exr" "$tmp/dot.exr" --max-rmse 0.2
err_has "gonio: diff: rmse 0.288675 > 0.2"
run 1 "|rel_bias| over the limit" "$tmp/black.exr" "$tmp/dot.exr" --max-rel-bias 0.5 --quiet
err_has "rel_bias"
check "--quiet prints no metrics" test ! -s "$tmp/d.out"
run 1 "max_err over the limit" "$tmp/black.exr" "$tmp/dot.exr" --max-error 0.99
run 0 "channels without the difference" "$tmp/black.exr" "$tmp/dot.exr" --channels G,B --max-error 0
run 1 "the channel with the difference" "$tmp/black.exr" "$tmp/dot.exr" --channels R --max-error 0

# Bad input: exit 1 with the file named.
run 1 "size mismatch" "$tmp/black.exr" "$tmp/wide.exr"
err_has "black.exr"; err_has "wide.exr"; err_has "2x2"; err_has "4x2"
run 1 "missing file" "$tmp/black.exr" "$tmp/missing.exr"
err_has "missing.exr"
run 1 "not an EXR" "$tmp/text.exr" "$tmp/black.exr"
err_has "text.exr"
run 1 "missing channel" "$tmp/black.exr" "$tmp/dot.exr" --channels Z
err_has "'Z'"

# Bad usage: exit 2 with the problem and where to look, as every command; --help: usage
# on stdout, exit 0.
run 2 "no arguments"
err_has "gonio diff: expected two images"
err_has "(see gonio diff --help)"
run 2 "unknown option" "$tmp/black.exr" "$tmp/dot.exr" --frobnicate
run 2 "missing value" "$tmp/black.exr" "$tmp/dot.exr" --max-rmse
run 2 "not a number" "$tmp/black.exr" "$tmp/dot.exr" --max-rmse 0.1x
run 2 "negative limit" "$tmp/black.exr" "$tmp/dot.exr" --max-error -1
run 2 "three images" "$tmp/black.exr" "$tmp/dot.exr" "$tmp/dot.exr"
run 0 "--help" --help
check "--help prints the usage" grep -q "usage: gonio diff" "$tmp/d.out"

finish
