# lib.sh: helpers for the regression scripts (sourced). Each script counts checks with
# pass/fail, and ends with `finish`, which prints "NAME: N passed, N failed" and exits.
# A check whose command takes longer than the budget of a test (10 s, tests/README.md)
# prints a note with its time.
set -u
name=$(basename "$0" .sh)
n_pass=0
n_fail=0
tmp=${TEST_TMP:-$(mktemp -d)}/$(basename "$(dirname "$0")")/$name
mkdir -p "$tmp"
TEST_BUDGET_S=10
# The scripts' Python (the standard library only) is Debian's where it is there: a version
# manager's shim first on PATH costs about 75 ms a call, and a run calls Python hundreds of
# times.
if [ -x /usr/bin/python3 ]; then python3() { /usr/bin/python3 "$@"; }; fi
# It imports tests/tool's modules by name: gltf_fixture (the scenes and images the scripts
# write) and exrtool (an EXR reader of its own).
PYTHONPATH=$(cd "$(dirname "${BASH_SOURCE[0]}")/tool" && pwd)${PYTHONPATH:+:$PYTHONPATH}
export PYTHONPATH
pass() { n_pass=$((n_pass + 1)); }
fail() { n_fail=$((n_fail + 1)); echo "  FAIL: $*"; }
# over_budget WHAT T0: the note for a check that started at $EPOCHREALTIME T0, if it was slow.
over_budget() {
    awk -v a="$2" -v b="$EPOCHREALTIME" -v lim=$TEST_BUDGET_S -v what="$1" \
        'BEGIN { if (b - a > lim) printf "  note: \"%s\" took %.1f s, over the %d s budget of a test (tests/README.md)\n", what, b - a, lim }'
}
check() { # check DESCRIPTION COMMAND...: passes when the command succeeds
    local what=$1 t0=$EPOCHREALTIME; shift
    if "$@" >"$tmp/out" 2>&1; then pass; else fail "$what"; sed 's/^/    /' "$tmp/out" | tail -n 20; fi
    over_budget "$what" "$t0"
}
check_fails() { # check_fails DESCRIPTION EXPECTED_STATUS COMMAND...
    local what=$1 want=$2 t0=$EPOCHREALTIME; shift 2
    "$@" >"$tmp/out" 2>&1
    local got=$?
    cp "$tmp/out" "$tmp/last" # what the command printed, for checks that follow
    if [ "$got" = "$want" ]; then pass; else fail "$what (exit $got, expected $want)"; sed 's/^/    /' "$tmp/out" | tail -n 20; fi
    over_budget "$what" "$t0"
}
skip_all() { echo "  skipped: $*"; exit 77; }
# in_tier fast|slow: whether this run has that tier's checks ($GONIO_TEST_TIER, which
# tests/run.sh sets: fast, slow or full; a script run by hand has both). A script with slow
# checks puts them under `if in_tier slow; then`, and tests/run.sh runs it in the slow tier
# too; its fast checks go under `if in_tier fast; then` (tests/README.md).
in_tier() {
    case ${GONIO_TEST_TIER:-full} in full) return 0 ;; "$1") return 0 ;; *) return 1 ;; esac
}
finish() {
    echo "$name: $n_pass passed, $n_fail failed"
    [ "$n_fail" = 0 ]
}

# Renders that share a kernel, run in one process (gonio batch: one device, each kernel
# compiled once; on lavapipe most of a small render's time is its kernel's compilation):
# queue ID [NAME=value...] COMMAND ARGS... adds a gonio command line (the words as given; no
# single quotes in them); run_queue runs what is queued, then queued ID gives that line's
# exit status and leaves its output (stdout and stderr) in $tmp/last, and check_queued
# DESCRIPTION STATUS ID checks the status as check_fails does; after_queue (below) defers a
# check until the queue has run. A line's result is exactly
# the same command's in a process of its own (tests/regress/batch.sh).
# after_queue COMMAND ARGS... runs COMMAND ARGS (the checks on a queued line's results) after
# the next run_queue, in the order they were given.
queue_ids=() queue_after=()
after_queue() { queue_after+=("$(printf '%q ' "$@")"); }
queue() {
    local id=$1 w line=""; shift
    for w in "$@"; do
        case $w in *"'"* | *$'\n'*) fail "queue $id: a word with a quote or a newline: '$w'"; return 1 ;; esac
        line+="'$w' "
    done
    queue_ids+=("$id")
    printf '%s\n' "$line" >>"$tmp/queue.txt"
}
run_queue() {
    local n=0 id
    rm -rf "$tmp/queue"
    mkdir -p "$tmp/queue"
    "$GONIO" batch "$tmp/queue.txt" --logs "$tmp/queue" >"$tmp/queue/batch.log" 2>&1
    local rc=$?
    # The batch's own failures, which no line's status shows: 0 or 1 (a line failed) only,
    # and nothing said at its end by the validation layer or a sanitizer (of the device
    # it kept, or of memory it leaked).
    if [ $rc -gt 1 ] || grep -q 'validation\|Sanitizer\|runtime error' "$tmp/queue/batch.log"; then
        fail "the batch itself (exit $rc)"; sed 's/^/    /' "$tmp/queue/batch.log" | tail -n 20
    fi
    for id in "${queue_ids[@]}"; do
        n=$((n + 1))
        mv "$tmp/queue/$n.status" "$tmp/queue/$id.status" 2>/dev/null
        mv "$tmp/queue/$n.log" "$tmp/queue/$id.log" 2>/dev/null
        # a queued line over the budget of a test gets the note a check would
        awk -v lim=$TEST_BUDGET_S -v id="$id" '$1 > lim { printf "  note: queued line \"%s\" took %.1f s, over the %d s budget of a test (tests/README.md)\n", id, $1, lim }' \
            "$tmp/queue/$n.time" 2>/dev/null
    done
    queue_ids=()
    rm -f "$tmp/queue.txt"
    local after=("${queue_after[@]}") a
    queue_after=()
    for a in "${after[@]}"; do eval "$a"; done
}
queued() {
    cp "$tmp/queue/$1.log" "$tmp/last" 2>/dev/null || echo "no line $1 in the batch" >"$tmp/last"
    cat "$tmp/queue/$1.status" 2>/dev/null || echo missing
}
queued_ok() { # queued_ok ID...: whether every line ID exited 0 ($tmp/last: the first failed one's output)
    local id
    for id; do [ "$(queued "$id")" = 0 ] || return 1; done
}
check_queued() {
    local got
    got=$(queued "$3")
    if [ "$got" = "$2" ]; then pass; else fail "$1 (exit $got, expected $2)"; sed 's/^/    /' "$tmp/last" | tail -n 20; fi
}

# fixture NAME COMMAND...: the path of a file that several scripts use, made once a run.
# COMMAND makes it, with the first {} in its arguments standing for the file it writes
# (a name with NAME's extension); it runs in
# the first script that asks, under a lock, while the others wait for it. Prints the path;
# a COMMAND that fails (or writes nothing) makes every asker fail, with its output.
# $TEST_FIXTURES is the run's fixture folder (tests/run.sh); a script run alone gets its own.
fixture() {
    local fname=$1; shift
    local dir=${TEST_FIXTURES:-${TEST_TMP:-$tmp}/fixtures}
    local f=$dir/$fname part=$dir/.part-$fname args=() a done_=0
    for a in "$@"; do
        if [ $done_ = 0 ] && [ "$a" = "{}" ]; then args+=("$part"); done_=1; else args+=("$a"); fi
    done
    mkdir -p "$dir"
    (
        flock 9
        [ -e "$f" ] && exit 0
        [ -e "$f.failed" ] && { cat "$f.failed" >&2; exit 1; }
        if "${args[@]}" >"$f.log" 2>&1 && [ -s "$part" ]; then
            mv "$part" "$f"
        else
            { echo "fixture $fname: '${args[*]}' failed:"; cat "$f.log"; } >"$f.failed"
            cat "$f.failed" >&2
            exit 1
        fi
    ) 9>"$f.lock" || return 1
    echo "$f"
}

# write_scenes <<'PY' ... PY: runs that Python, which writes the script's scenes into the
# folder it is given (sys.argv[1], the script's $tmp; gltf_fixture builds them). Without
# python3 the script is skipped, and where the scenes cannot be written it fails and ends:
# call it before any check.
write_scenes() {
    command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
    python3 - "$tmp" || { fail "scenes"; finish; exit; }
}

# ---- checks several scripts make --------------------------------------------------------
# same_halves A.exr LEFT.exr RIGHT.exr WIDTH: A's left half is LEFT's and its right half
# RIGHT's, pixel by pixel (R, G and B within 1e-4, relative above 1; the two columns at the
# seam are not compared), and LEFT and RIGHT differ somewhere by more than 0.01, or the check
# proves nothing; LEFT and RIGHT may be one file (A is that image, but at the seam).
# (The renders of a quad whose texture splits it in two against untextured twins of its
# halves: slots.sh, specgloss.sh.)
same_halves() {
    python3 - "$@" <<'PY'
import sys
import exrtool
def rgb(path):
    _, ch = exrtool.read(path)
    return [ch[c][1] for c in "RGB"]
t, l, r = rgb(sys.argv[1]), rgb(sys.argv[2]), rgb(sys.argv[3])
one = sys.argv[2] == sys.argv[3]
w = int(sys.argv[4])
bad = differ = 0
for c in range(3):
    for i, v in enumerate(t[c]):
        x = i % w
        if x in (w // 2 - 1, w // 2):
            continue
        want = l[c][i] if x < w // 2 else r[c][i]
        if abs(v - want) > 1e-4 * max(1.0, abs(want)):
            bad += 1
            if bad <= 5: print("pixel %d channel %d: %.6f, not %.6f" % (i, c, v, want))
        differ += abs(l[c][i] - r[c][i]) > 0.01
print("%d values wrong, %d differ between the two references" % (bad, differ))
sys.exit(1 if bad or (differ == 0 and not one) else 0)
PY
}

# need_denoiser WHAT: ends the script here where gonio has no Open Image Denoise (make
# denoiser) and GONIO_OIDN_LIB names none: skipped, saying that WHAT did not run, when no
# check has failed; a failure instead where GONIO_REQUIRE_DENOISER=1 (CI) requires it.
need_denoiser() {
    local lib
    lib=$(dirname "$GONIO")/../oidn/lib/libOpenImageDenoise.so.2
    [ -e "$lib" ] || [ -n "${GONIO_OIDN_LIB:-}" ] && return 0
    if [ "${GONIO_REQUIRE_DENOISER:-}" = 1 ]; then
        fail "Open Image Denoise is required here (GONIO_REQUIRE_DENOISER=1) but $lib is absent"
        finish
        exit 1
    fi
    [ "$n_fail" = 0 ] || { finish; exit 1; }
    skip_all "no Open Image Denoise at $lib (make denoiser fetches it): $1"
}

# ---- gonio preview in a virtual X display (preview.sh, denoise_preview.sh) ---------------
# in_xvfb "$@": runs the script again inside one virtual X display (xvfb-run -a: a free
# server number; 24-bit for Vulkan), or skips it where a tool is missing. First thing.
in_xvfb() {
    [ "${GONIO_PREVIEW_XVFB:-}" = 1 ] && return 0
    local t
    for t in xvfb-run xauth xdotool import compare identify; do
        command -v $t >/dev/null || skip_all "$t is missing (make test-deps installs it)"
    done
    GONIO_PREVIEW_XVFB=1 exec xvfb-run -a -s "-screen 0 320x240x24" "$0" "$@"
}
# same_image A.png B.png: same size, no channel of any pixel more than one level apart, and
# at most 1% of the pixels different at all (GLSL's float pow may round the odd value
# otherwise than image.c's double one; a systematic error changes most pixels).
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
# wait_for FILE PATTERN: until FILE has a line matching PATTERN (grep; at most 60 s). A test
# that signals a render waits so for its first progress line (a log's: "gonio:   0% ...", a
# second into the passes, once the handlers are in place), never for a fixed time.
wait_for() { for _ in $(seq 600); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done; return 1; }
# preview_open OUT ARGS...: starts `gonio preview ARGS` in the background (its stdout in
# OUT.out, stderr in OUT.err; stopped after 120 s) and finds its window: $pid, $wid (empty
# when no window opened within 30 s). preview_close OUT: Esc; the preview exits 0 (2 checks).
preview_open() {
    local out=$1; shift
    timeout 120 "$GONIO" preview "$@" >"$out.out" 2>"$out.err" &
    pid=$!
    wid=$(timeout 30 xdotool search --sync --name '^gonio preview')
}
preview_close() {
    check "Esc" xdotool key Escape
    wait $pid
    local rc=$?
    [ $rc = 0 ] && pass || { fail "preview exit status $rc"; cat "$1.err"; }
}
# wait_title PATTERN: waits up to $title_wait_s seconds (30 unless set) for the title of the
# window $wid to match PATTERN (grep -E)
wait_title() {
    local i
    for i in $(seq $((${title_wait_s:-30} * 10))); do
        xdotool getwindowname "$wid" 2>/dev/null | grep -Eq "$1" && return 0
        sleep 0.1
    done
    echo "title: $(xdotool getwindowname "$wid" 2>&1)"; return 1
}
