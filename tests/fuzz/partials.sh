#!/usr/bin/env bash
# partials.sh [N]: N random damages (default 2000) of resumable partials and tile sets, each
# given to the real program (make fuzz-partials; run it with the sanitizer build:
# GONIO=build/sanitize/gonio). A damaged partial goes to `gonio render --resume`, a damaged
# tile with its good neighbour to `gonio merge`. Every run must end with exit 0, 1 or 2, in
# time, with no sanitizer report; and a run that exits 0 must have written only finite
# values. Damages (tests/tool/exrtool.py mutate): values set to NaN, Inf, negative, huge or
# fractional; a channel stored as half or uint; gonio:spp changed; the data window moved;
# a channel removed or added; bytes flipped, cut or overwritten.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
N=${1:-2000}
GONIO=$(realpath "${GONIO:-build/sanitize/gonio}")
X="python3 $root/tests/tool/exrtool.py"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:quarantine_size_mb=16"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$root/tests/lsan.supp:print_suppressions=0"
export VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)}
S=scenes/cornell.gltf
R="--size 12x8 --quiet --compression none"
"$GONIO" render $S -o "$tmp/part.exr" $R --spp 2 --resumable --aov depth,variance || exit 1
"$GONIO" render $S -o "$tmp/left.exr" $R --spp 2 --crop 0,0,6,8 || exit 1
"$GONIO" render $S -o "$tmp/right.exr" $R --spp 2 --crop 6,0,12,8 || exit 1

declare -A outcome
bad=0
for ((i = 0; i < N; i++)); do
    rm -f "$tmp/out.exr"
    if ((i % 2 == 0)); then
        $X mutate "$tmp/part.exr" "$tmp/in.exr" "$i"
        timeout 120 "$GONIO" render $S -o "$tmp/out.exr" $R --spp 4 --resume "$tmp/in.exr" --aov depth,variance \
            >"$tmp/log" 2>&1
    else
        $X mutate "$tmp/right.exr" "$tmp/in.exr" "$i"
        timeout 120 "$GONIO" merge "$tmp/left.exr" "$tmp/in.exr" -o "$tmp/out.exr" --compression none >"$tmp/log" 2>&1
    fi
    rc=$?
    what=$([ $((i % 2)) = 0 ] && echo resume || echo merge)
    problem=""
    case $rc in
        0 | 1 | 2) ;;
        124) problem="hung (killed after 120 s)" ;;
        *) problem="exit $rc" ;;
    esac
    if grep -q "ERROR: AddressSanitizer\|ERROR: LeakSanitizer\|runtime error:" "$tmp/log"; then
        problem="sanitizer report"
    fi
    if [ $rc = 0 ] && [ -z "$problem" ]; then
        nf=$($X nonfinite "$tmp/out.exr" 2>&1)
        [ "$nf" = 0 ] || problem="exit 0 with $nf NaN or infinite values written"
    fi
    key="$what exit $rc"
    outcome[$key]=$((${outcome[$key]:-0} + 1))
    if [ -n "$problem" ]; then
        bad=$((bad + 1))
        cp "$tmp/in.exr" "$root/partial-failure-$i.exr"
        echo "FAIL: damage $i ($what): $problem; input kept as partial-failure-$i.exr"
        sed 's/^/    /' "$tmp/log" | head -20
    fi
done
for k in "${!outcome[@]}"; do echo "$k: ${outcome[$k]}"; done | sort
echo "partials: $N damaged inputs, $bad problem(s)"
[ "$bad" = 0 ]
