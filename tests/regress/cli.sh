#!/usr/bin/env bash
# cli.sh: what every command shares: --opt=value is --opt value, unknown options are
# reported as such (exit 2) without taking the next argument.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=$PWD/scenes/cornell.gltf

# ---- the slow tier (lib.sh: in_tier) ---------------------------------------------------------
if in_tier slow; then
    # compare.sh sweeps the built-in teapot in the fast tier, and the commands run from
    # elsewhere below show that nothing reads the source tree
    mkdir -p "$tmp/elsewhere-slow"
    check "compare --sweep, elsewhere" sh -c \
        "cd '$tmp/elsewhere-slow' && exec '$G' compare --sweep 1,2 teapot -o sweep --size 16x16 --quiet"
    # ...and while the image is being written (a large one): the temporary file is removed.
    rm -f "$tmp/b.err"
    "$G" render $C -o "$tmp/big.exr" --size 6000x6000 --mode depth --time 60 2>"$tmp/b.err" &
    pid=$!
    wait_for "$tmp/b.err" 'spp'
    kill -INT $pid
    for _ in $(seq 2000); do ls -a "$tmp" | grep -q '\.big\.exr\.tmp-' && break; sleep 0.005; done
    if ls -a "$tmp" | grep -q '\.big\.exr\.tmp-'; then
        kill -INT $pid
        wait $pid
        rc=$?
        check "SIGINT during the write: exit 130 (got $rc)" test $rc = 130
        check "SIGINT during the write: no output, no temporary file" \
            sh -c "! ls -a '$tmp' | grep -q 'big\.exr'"
    else
        wait $pid
        echo "  note: the write ended before it could be interrupted: not checked"
    fi
fi
in_tier fast || { finish; exit; }

# The commands that open a device run in one batch (lib.sh: queue); the checks read each
# line's status and output ($tmp/last) once it has run.
queue sp render $C -o "$tmp/sp.exr" --mode phong --spp 2 --size 24x16 --seed 3 --quiet
queue eq render $C --output="$tmp/eq.exr" --mode=phong --spp=2 --size=24x16 --seed=3 --quiet
queue other render $C -o "$tmp/other.exr" --mode phong --spp 2 --size 24x16 --seed 4 --quiet
queue bench bench --generate=2000 --size=16x16 --seconds=0.05
queue cmp compare $C --modes=flat,phong --spp=1 --size=16x16 --output="$tmp/cmp" --quiet
# warns MODE-AND-OPTIONS... -- WARNING: queues a render that must succeed with WARNING on
# stderr (an option the mode or outputs do not use is a warning, not silence); its check
# runs after the batch.
nw=0
warns() {
    local args=() want
    while [ "$1" != -- ]; do args+=("$1"); shift; done
    want=$2
    nw=$((nw + 1))
    queue "w$nw" render $C -o "$tmp/w$nw.exr" --size 8x8 --spp 1 --quiet "${args[@]}"
    after_queue warns_check "w$nw" "$want" "${args[*]}"
}
warns_check() {
    if queued_ok "$1" && grep -q "warning: $2" "$tmp/last"; then pass
    else fail "render $3: expected a warning '$2', got: $(cat "$tmp/last")"; fi
}
for o in "--max-depth 3" "--estimator light"; do
    warns --mode phong $o -- "${o% *} applies to --mode path only; ignored with --mode phong"
done
warns --mode flat --brdf lambert -- "--brdf applies to --mode path (and albedo"
warns --ambient 0.5 -- "--ambient applies to the local modes only"
warns --no-shadows -- "--no-shadows applies to the local modes only"
warns --exposure 1 -- "--exposure applies to the PNG only"
warns --tonemap=aces -- "--tonemap applies to the PNG only"
warns --time 0.1 --spp 4 -- "--spp is ignored with --time"
queue apply render $C -o "$tmp/w.exr" --png "$tmp/w.png" --size 8x8 --spp 1 --max-depth 2 --brdf lambert \
    --estimator bsdf --exposure 1 --tonemap aces --quiet
queue albedo render $C -o "$tmp/w.exr" --size 8x8 --spp 1 --mode albedo --brdf lambert --ambient 1 --no-shadows --quiet
run_queue # the warnings' checks run here (after_queue)
check "options that apply: no warning" sh -c "[ \"\$(cat '$tmp/queue/apply.status')\" = 0 ] && test ! -s '$tmp/queue/apply.log'"
check "albedo with --brdf, --ambient, --no-shadows: no warning about --brdf" sh -c "! grep -q brdf '$tmp/queue/albedo.log'"

# ---- --opt=value --------------------------------------------------------------------------
# The same command in both forms gives the same bits.
check_queued "render --opt value" 0 sp
check_queued "render --opt=value" 0 eq
check "render: both forms, identical pixels" "$G" diff "$tmp/sp.exr" "$tmp/eq.exr" --max-error=0 --quiet
check_queued "render another seed" 0 other
check_fails "diff --max-error=0 on other pixels fails" 1 "$G" diff "$tmp/sp.exr" "$tmp/other.exr" --max-error=0 --quiet
check "teapot --level=2 --output=" "$G" teapot --level=2 --output="$tmp/t-eq.gltf"
check "teapot --level 2 -o" "$G" teapot --level 2 -o "$tmp/t-sp.gltf"
check "teapot: both forms, the same file" cmp "$tmp/t-eq.gltf" "$tmp/t-sp.gltf"
check "scene cornell --output=" "$G" scene cornell --output="$tmp/c.gltf"
check "merge --output=" "$G" merge "$tmp/sp.exr" "$tmp/eq.exr" --force --output="$tmp/m.exr" # one seed twice
check "merged: 4 spp" sh -c "exrheader '$tmp/m.exr' | grep -q 'gonio:spp (type int): 4'"
check_queued "bench --generate=N --size= --seconds=" 0 bench
check "brdf MODEL --PARAM=V --theta=" "$G" brdf phong --exponent=8 --theta=45 --output="$tmp/lobe.png" --size=240x240
check_queued "compare --modes= --spp= --size= --output=" 0 cmp
check "compare wrote flat.exr" test -s "$tmp/cmp/flat.exr"
# Each option's own parser sees the value: its own message, naming the value.
for c in "render $C -o $tmp/x.exr --spp" "preview $C --frames" "bench --seconds" "brdf phong --theta" \
    "compare $C -o $tmp/cmp --spp" "teapot -o $tmp/x.gltf --level" "diff $tmp/sp.exr $tmp/eq.exr --max-rmse"; do
    check_fails "${c%% *} ${c##* }=bogus: a usage error" 2 "$G" $c=bogus
    check "${c%% *} ${c##* }=bogus: the option's own message" \
        sh -c "grep -q bogus '$tmp/last' && ! grep -q 'unknown option' '$tmp/last'"
done
# ... and says it once, whether the option's parser or the list it completes from words it.
for o in "--mode bogus" "--sampler bogus" "--aov bogus" "--tonemap bogus"; do
    check_fails "render $o: a usage error" 2 "$G" render $C -o "$tmp/x.exr" $o
    check "render $o: one message" test "$(grep -c bogus "$tmp/last")" = 1
done
# Options several commands take are defined once: the same range and message everywhere.
for c in "render $C -o $tmp/x.exr" "preview $C"; do
    check_fails "${c%% *} --max-depth 65537" 2 "$G" $c --max-depth 65537
    check "... names the range" grep -q "out of range: must be in \[0, 65536\]" "$tmp/last"
done
for c in "render $C -o $tmp/x.exr" "preview $C" "compare $C -o $tmp/cmp" "brdf lambert --sphere -o $tmp/b.exr"; do
    check_fails "${c%% *} --spp 0" 2 "$G" $c --spp 0
    check "... names the range" grep -q "out of range: must be in \[1, 16777216\]" "$tmp/last"
    check_fails "${c%% *} --size 0x8" 2 "$G" $c --size 0x8
    check "... names the range" grep -q "expected WxH, e.g. 640x480 (each 1..16384)" "$tmp/last"
done
check_fails "a flag given a value" 2 "$G" render $C -o "$tmp/x.exr" --quiet=yes
check "... says it takes none" grep -q -- "--quiet takes no value" "$tmp/last"
check "--name=value splits at the first =" "$G" brdf torrance-sparrow --exponent=64 --albedo

# ---- unknown options: reported as unknown, exit 2, whether last or not ------------------
for c in "render $C -o $tmp/x.exr" "preview $C" "info $C" devices "compare $C -o $tmp/cmp" merge diff \
    bench "brdf phong" "scene cornell" teapot; do
    for where in last middle; do
        if [ $where = last ]; then set -- --frobnicate; else set -- --frobnicate "$tmp/y.exr"; fi
        check_fails "${c%% *}: unknown option ($where)" 2 "$G" $c "$@"
        check "${c%% *}: unknown option ($where) is reported as unknown" \
            grep -q "unknown option '*--frobnicate" "$tmp/last"
    done
done
# ---- render: an option the mode or outputs do not use is a warning, not silence --------
# (queued with the renders above: warns)

# ---- gonio info: emitters and cameras ---------------------------------------------------
# The Cornell box's light is one quad (src/cli/cmd_scene.c); its camera stands at (0, 0.273,
# 0.8) looking down -Z with the published 39.3 degrees.
"$G" info $C >"$tmp/info.txt"
check "info: the Cornell box's light, 2 triangles" grep -q '^emissive  *2 triangles in 1 material(s): light (2)$' "$tmp/info.txt"
check "info: its camera, one line" grep -Eq '^camera 0 +"camera" position \(0, 0.273, 0.8\) forward \(0, 0, -1\) yfov 39.3[0-9]* deg$' "$tmp/info.txt"
A=${GONIO_ASSETS:-}/gltf
if [ -d "$A/EmissiveStrengthTest" ] && [ -d "$A/Cameras" ]; then
    # Five cubes (36 indices each), each with its own emissive material; the backdrop emits nothing.
    "$G" info "$A/EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf" >"$tmp/info2.txt"
    check "info: EmissiveStrengthTest, 60 triangles in 5 materials" \
        grep -q '^emissive  *60 triangles in 5 material(s): Emit4 (12), Emit2 (12), Emit1 (12), Emit8 (12), Emit16 (12)$' "$tmp/info2.txt"
    # Its node 1: translation (0.5, 0.5, 3), no rotation, yfov 0.7 rad = 40.107 degrees.
    "$G" info "$A/Cameras/glTF/Cameras.gltf" >"$tmp/info3.txt" 2>/dev/null
    check "info: Cameras.gltf's perspective camera" \
        grep -Eq '^camera 0 +".*" position \(0.5, 0.5, 3\) forward \(0, 0, -1\) yfov 40.1[01] deg$' "$tmp/info3.txt"
else
    echo "  note: \$GONIO_ASSETS has no EmissiveStrengthTest or Cameras: those info checks skipped"
fi

# ---- every command from any directory: no path into the source tree ----------------------
mkdir -p "$tmp/elsewhere"
# (one batch, run from there: relative paths are the batch's working directory's)
cd "$tmp/elsewhere" && {
    queue bench bench --size 16x16 --seconds 0.05
    queue paths bench --paths --size 16x16 --seconds 0.1 --reference 16x16:8
    queue scene scene cornell -o c.gltf
    queue teapot teapot --level 1 -o t.gltf
    queue render render c.gltf -o r.exr --png r.png --size 16x16 --spp 2 --quiet
    queue render2 render c.gltf -o r2.exr --size 16x16 --spp 2 --seed 1 --quiet
    queue merge merge r.exr r2.exr -o m.exr
    queue devices devices
    queue brdf brdf lambert --sphere -o b.exr --size 16x16 --spp 1
    queue compare compare c.gltf -o cmp --size 16x16 --spp 1 --modes flat,phong --quiet
    run_queue
    check_queued "bench without a scene, elsewhere" 0 bench
    cp "$tmp/last" bench.txt
    check "... is the built-in Cornell box (32 triangles)" sh -c \
        "grep -q '^scene  *cornell (built in)' bench.txt && grep -q '^triangles  *32$' bench.txt"
    check_queued "bench --paths without a scene, elsewhere" 0 paths
    check_queued "scene cornell, elsewhere" 0 scene
    check "... the same file as scenes/cornell.gltf" cmp c.gltf "$C"
    check_queued "teapot, elsewhere" 0 teapot
    check_queued "render, elsewhere" 0 render
    check_queued "render another seed, elsewhere" 0 render2
    check_queued "merge, elsewhere" 0 merge
    check "diff, elsewhere" "$G" diff r.exr m.exr --quiet
    check "info, elsewhere" "$G" info t.gltf
    check_queued "devices, elsewhere" 0 devices
    check_queued "brdf --sphere, elsewhere" 0 brdf
    check_queued "compare, elsewhere" 0 compare
    cd - >/dev/null
}

# ---- make install: the program, its man page, its bash completion ----------------------
inst=$tmp/inst
if command -v help2man >/dev/null && command -v man >/dev/null; then
    check "make install DESTDIR= PREFIX=/usr" make -s install DESTDIR="$inst" PREFIX=/usr config="${CONFIG:-release}"
    check "installed: bin/gonio runs" "$inst/usr/bin/gonio" --version
    MANWIDTH=100 man -l "$inst/usr/share/man/man1/gonio.1" >"$tmp/man.txt" 2>"$tmp/man.err"
    check "man -l renders the page" test -s "$tmp/man.txt"
    check "man: no roff warnings" test ! -s "$tmp/man.err"
    for want in "^NAME" "gonio - a physically based renderer" "^COMMANDS" "usage: gonio render SCENE" \
        "--max-depth N" "gonio teapot .--level N" "^EXIT STATUS" "130 after"; do
        check "man page has '$want'" grep -q -- "$want" "$tmp/man.txt"
    done
    comp=$inst/usr/share/bash-completion/completions/gonio
    # complete WORDS...: what the installed script offers for the last word.
    complete_words() {
        PATH="$inst/usr/bin:$PATH" bash -c '. "$0"; COMP_WORDS=("${@}"); COMP_CWORD=$(($# - 1))
            _gonio; complete -p gonio >/dev/null || exit 1; [ ${#COMPREPLY[@]} = 0 ] || printf "%s\n" "${COMPREPLY[@]}" | sort -u | tr "\n" " "' "$comp" "$@"
    }
    check "completion: gonio re -> render" test "$(complete_words gonio re)" = "render "
    check "completion: gonio render --mo -> --mode" test "$(complete_words gonio render --mo)" = "--mode "
    check "completion: --mode p -> path phong" test "$(complete_words gonio render c.gltf --mode p)" = "path phong "
    check "completion: gonio bench --p -> --paths" test "$(complete_words gonio bench --p)" = "--paths "
    check "completion: a BRDF model's parameters" test "$(complete_words gonio brdf phong --ex)" = "--exponent "
    check "completion: no guess after --spp" test -z "$(complete_words gonio render c.gltf --spp '')"
    mkdir -p "$tmp/files" && touch "$tmp/files/a.exr" "$tmp/files/b.png" "$tmp/files/c.gltf" "$tmp/files/d.glb"
    check "completion: diff offers EXRs" test "$(cd "$tmp/files" && complete_words gonio diff '')" = "a.exr "
    check "completion: render offers glTF files" test "$(cd "$tmp/files" && complete_words gonio render '')" = "c.gltf d.glb "
    check "completion: --png offers PNGs" test "$(cd "$tmp/files" && complete_words gonio render c.gltf --png '')" = "b.png "
    check "completion: --env offers maps and studio" \
        test "$(cd "$tmp/files" && complete_words gonio render c.gltf --env '')" = "a.exr studio "
    check "completion: scene offers its scenes" test "$(complete_words gonio scene '')" = "cornell teapot "
    # The program's option tables are the one source: every long option each command's
    # --help lists (so any option added to a table) is offered, nothing else is, and the
    # script itself names none of them.
    all_opts=
    for c in render preview info devices compare merge diff bench brdf "brdf phong" scene teapot denoise; do
        want=$({ "$G" $c --help | sed -n 's/^ \{1,4\}\(-[-a-zA-Z]*\)\(, \(--[-a-z]*\)\)\{0,1\}.*/\1 \3/p'
            echo --help; } | tr ' ' '\n' | grep -- '^--' | grep -v -- '--PARAM' | sort -u | tr '\n' ' ')
        check "completion: gonio $c -- offers the options of its --help" \
            test "$(complete_words gonio $c --)" = "$want"
        all_opts="$all_opts $want"
    done
    named=$(for o in $all_opts; do grep -qF -- "$o" "$comp" && echo "$o"; done | sort -u | tr '\n' ' ')
    check "completion: the script names no option ($named)" test -z "$named"
else
    echo "  note: help2man or man is missing (make test-deps installs them): make install not checked"
fi

# ---- progress ---------------------------------------------------------------------------
# Not a terminal (a log): plain lines, none before a second has passed, then one a tenth;
# with --time the percentage is the time's (each line's within 1 of 100 elapsed / limit).
"$G" render $C -o "$tmp/p.exr" --size 32x32 --time 2 2>"$tmp/p.err"
check "log: no carriage returns" sh -c "! grep -q \$(printf '\r') '$tmp/p.err'"
grep -E '^gonio: +[0-9]+%  [0-9]+ spp  [0-9.]+ spp/s  [0-9.]+ M paths/s  [0-9.]+ s  ' "$tmp/p.err" >"$tmp/p.lines"
n=$(wc -l <"$tmp/p.lines")
check "log: 3 to 11 progress lines (got $n)" test "$n" -ge 3 -a "$n" -le 11
check "log: each line has an ETA, the last says done" sh -c \
    "head -n -1 '$tmp/p.lines' | grep -vq 'ETA' && exit 1; tail -n 1 '$tmp/p.lines' | grep -q '100%.* done$'"
# elapsed() in awk: the seconds before "ETA" or "done" (printed to 0.1 s: 2.5% of 2 s).
E='function elapsed() { match($0, /[0-9.]+ s  (ETA|done)/); return substr($0, RSTART) + 0 }'
check "log: --time progress is the time's" awk "$E"'{ p = $2 + 0; e = 50 * elapsed();
    if ($NF != "done" && (p > e + 4 || p < e - 4)) { print "line: " $0; bad = 1 } } END { exit bad }' "$tmp/p.lines"
check "log: no line before a second" awk "$E"'{ if (elapsed() < 0.95 && $NF != "done") bad = 1 } END { exit bad }' "$tmp/p.lines"
"$G" render $C -o "$tmp/p.exr" --size 32x32 --mode phong --spp 4000 2>"$tmp/p2.err"
check "log: --spp progress counts spp" grep -Eq '^gonio: +[0-9]+%  [0-9]+/4000 spp .* Mrays/s .* ETA [0-9.]+ s$' "$tmp/p2.err"
"$G" render $C -o "$tmp/p.exr" --size 32x32 --time 1.5 --quiet 2>"$tmp/p3.err"
check "--quiet: nothing on stderr" test ! -s "$tmp/p3.err"
if command -v script >/dev/null; then
    script -qec "'$G' render '$C' -o '$tmp/p.exr' --size 32x32 --spp 64" /dev/null >"$tmp/tty.out" 2>&1
    check "terminal: a bar redrawn in place with rate and ETA" \
        grep -Eq "$(printf '\r')"'\[#* *\] +[0-9]+%  [0-9]+/64 spp  [0-9.]+ spp/s  [0-9.]+ M paths/s  [0-9.]+ s  (ETA|done)' "$tmp/tty.out"
else
    echo "  note: script(1) is missing: the terminal progress bar is not checked"
fi

# ---- interrupts ---------------------------------------------------------------------------
# SIGINT (or SIGTERM) once: the render ends after its pass, writes what it has, exits 128 + N.
for sig in INT TERM; do
    want=$((128 + $(kill -l $sig)))
    rm -f "$tmp/i.exr" "$tmp/i.err" # (wait_for must not read the render before's messages)
    "$G" render $C -o "$tmp/i.exr" --png "$tmp/i.png" --size 32x32 --time 60 2>"$tmp/i.err" &
    pid=$!
    wait_for "$tmp/i.err" 'ETA'
    kill -$sig $pid
    wait $pid
    rc=$?
    check "SIG$sig: exit $want (got $rc)" test $rc = $want
    check "SIG$sig: the EXR and PNG are written" test -s "$tmp/i.exr" -a -s "$tmp/i.png"
    spp=$(exrheader "$tmp/i.exr" 2>/dev/null | sed -n 's/.*gonio:spp (type int): //p')
    check "SIG$sig: its gonio:spp is what was rendered ($spp)" grep -q "writing the $spp spp" "$tmp/i.err"
    check "SIG$sig: the progress line says interrupted" grep -Eq '^gonio: +[0-9]+% .* interrupted$' "$tmp/i.err"
    check "SIG$sig: no temporary file left" sh -c "! ls -a '$tmp' | grep -q tmp-"
done
# Twice: at once, status 130, no output at all.
rm -f "$tmp/i.exr" "$tmp/i.err"
"$G" render $C -o "$tmp/i.exr" --size 512x512 --time 60 2>"$tmp/i.err" &
pid=$!
wait_for "$tmp/i.err" 'ETA'
kill -INT $pid
wait_for "$tmp/i.err" 'stopping after this pass'
kill -INT $pid
wait $pid
check "SIGINT twice: exit 130 (got $?)" test $? = 130
check "SIGINT twice: no output" test ! -e "$tmp/i.exr"

check "no output after usage errors" test ! -e "$tmp/x.exr"
finish
