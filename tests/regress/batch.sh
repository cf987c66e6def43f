#!/usr/bin/env bash
# batch.sh: `gonio batch`: its lines render what the same command lines give run one process
# each (bit for bit, the references made by separate processes); per-line logs and exit
# statuses; a failing line neither stops the others nor hides its status; NAME=value applies
# to its line only; quoting, comments, and its own errors.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=scenes/cornell.gltf
R="--spp 3 --size 24x24 --quiet"

# The references: one process each.
"$G" render $C -o "$tmp/ref-1.exr" $R --seed 1 &&
    "$G" render $C -o "$tmp/ref-2.exr" $R --seed 2 --aov albedo,normal &&
    "$G" render scenes/teapot.gltf -o "$tmp/ref-3.exr" $R --mode phong &&
    GONIO_WALK_ARRAY=1 "$G" render $C -o "$tmp/ref-4.exr" $R --brdf ggx || fail "the reference renders"

mkdir -p "$tmp/logs"
cat >"$tmp/jobs.txt" <<EOF
# the same renders, in one process
render $C -o '$tmp/b-1.exr' $R --seed 1
render $C -o "$tmp/b-2.exr" $R --seed 2 --aov albedo,normal

render scenes/teapot.gltf -o $tmp/b-3.exr $R --mode phong   # a comment after a line
GONIO_WALK_ARRAY=1 render $C -o $tmp/b-4.exr $R --brdf ggx
render $C -o $tmp/b-5.exr $R --brdf nosuch
render $tmp/none.gltf -o $tmp/b-6.exr $R
sh -c 'exit 0'
preview $C
render $C -o '$tmp/b-9.exr $R
info $C
EOF
check_fails "a batch with failing lines exits 1" 1 "$G" batch "$tmp/jobs.txt" --logs "$tmp/logs"
for k in 1 2 3 4; do
    check "render $k of the batch: the pixels of its own process" "$TESTTOOL" same "$tmp/ref-$k.exr" "$tmp/b-$k.exr"
done
check "... its own header (the line's command)" sh -c "exrheader '$tmp/b-4.exr' | grep -a 'gonio:command' | grep -q 'gonio render $C -o $tmp/b-4.exr'"
status() { cat "$tmp/logs/$1.status" 2>/dev/null; }
check "each line's status: 0 for the renders" test "$(status 2)$(status 3)$(status 5)$(status 6)" = 0000
check "... 2 for a usage error (line 7)" test "$(status 7)" = 2
check "... 1 for a missing scene (line 8)" test "$(status 8)" = 1
check "... 2 for an unknown command, preview and a broken quote (lines 9-11)" test "$(status 9)$(status 10)$(status 11)" = 222
check "... and the lines after them ran (line 12)" test "$(status 12)" = 0
check "no log or status for comments and blank lines" test ! -e "$tmp/logs/1.log" -a ! -e "$tmp/logs/4.status"
check "each line's wall time: seconds, a render's more than an info's" awk \
    'FNR == 1 { t[FILENAME] = $1 + 0; if ($0 !~ /^[0-9]+\.[0-9][0-9][0-9]$/) bad = 1 }
     END { exit bad || !(t[ARGV[1]] > t[ARGV[2]]) }' "$tmp/logs/2.time" "$tmp/logs/12.time"
check "each line's messages in its own log" grep -q "unknown BRDF model 'nosuch'" "$tmp/logs/7.log"
check "... naming the file" grep -q "none.gltf" "$tmp/logs/8.log"
check "... stdout too" grep -q "^triangles" "$tmp/logs/12.log"
check "... and the batch's own stderr says which lines failed" sh -c \
    "grep -q 'jobs.txt:7 gave exit status 2' '$tmp/last' && grep -q 'jobs.txt:8 gave exit status 1' '$tmp/last'"
check "the broken quote named" grep -q "jobs.txt:11: an unterminated quote" "$tmp/logs/11.log"
check "preview refused" grep -q "'preview' cannot run in a batch" "$tmp/logs/10.log"

# NAME=value holds for its line only: the loop cap's debug line is in the first line's log,
# not in the second's.
cat >"$tmp/env.txt" <<EOF
GONIO_LOOP_CAP=3000 GONIO_DEBUG_RESUMES=1 render $C -o $tmp/e-1.exr $R --seed 1
render $C -o $tmp/e-2.exr $R --seed 1
EOF
mkdir -p "$tmp/envlogs"
check "a batch of two lines" "$G" batch "$tmp/env.txt" --logs "$tmp/envlogs"
check "... the first with its variables" grep -q "gonio: debug: .*dispatch" "$tmp/envlogs/1.log"
check "... the second without them" sh -c "test -s '$tmp/envlogs/2.log' -o -e '$tmp/envlogs/2.status' && ! grep -q 'debug' '$tmp/envlogs/2.log'"
check "... both the pixels of one process" sh -c "'$TESTTOOL' same '$tmp/ref-1.exr' '$tmp/e-1.exr' && '$TESTTOOL' same '$tmp/ref-1.exr' '$tmp/e-2.exr'"
# A line that sets what the Vulkan loader or a driver reads gets a device of its own, as
# `gonio LINE` would (an ICD file that is not there: no device, exit 1, as alone), not the
# one the line before left; a line that sets what the dynamic loader reads at a program's
# start (LD_PRELOAD) cannot be honoured in a running process and is refused (exit 2).
cat >"$tmp/drv.txt" <<EOF
render $C -o $tmp/d-1.exr $R --seed 1
VK_ICD_FILENAMES=$tmp/none.json render $C -o $tmp/d-2.exr $R --seed 1
LD_PRELOAD=$tmp/none.so render $C -o $tmp/d-3.exr $R --seed 1
render $C -o $tmp/d-4.exr $R --seed 1
EOF
mkdir -p "$tmp/drvlogs"
check_fails "a batch whose lines change the driver" 1 "$G" batch "$tmp/drv.txt" --logs "$tmp/drvlogs"
check "... the VK_ICD_FILENAMES line fails as alone: no Vulkan device" sh -c "test \$(cat '$tmp/drvlogs/2.status') = 1 && grep -q 'cannot create a Vulkan instance' '$tmp/drvlogs/2.log'"
check "... the LD_PRELOAD line is refused, saying why" sh -c "test \$(cat '$tmp/drvlogs/3.status') = 2 && grep -q 'LD_PRELOAD is read by the dynamic loader' '$tmp/drvlogs/3.log'"
check "... the lines around them render, the pixels of one process" sh -c "'$TESTTOOL' same '$tmp/ref-1.exr' '$tmp/d-1.exr' && '$TESTTOOL' same '$tmp/ref-1.exr' '$tmp/d-4.exr'"
check "a batch from standard input" sh -c "echo 'render $C -o $tmp/s-1.exr $R --seed 1' | '$G' batch -"
check "... renders" "$TESTTOOL" same "$tmp/ref-1.exr" "$tmp/s-1.exr"
# A line's --variant, --at and --allow-outside-files do not reach the lines after it.
mkdir -p "$tmp/outside/in"
python3 - "$C" "$tmp/outside/in/var.gltf" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d.setdefault("extensionsUsed", []).append("KHR_materials_variants")
d.setdefault("extensions", {})["KHR_materials_variants"] = {"variants": [{"name": "red"}]}
json.dump(d, open(sys.argv[2], "w"))
PY
cat >"$tmp/state.txt" <<EOF
render $tmp/outside/in/var.gltf -o $tmp/v-1.exr $R --variant red
render $C -o $tmp/v-2.exr $R --seed 1
EOF
mkdir -p "$tmp/statelogs"
check "a --variant line, then a file without that variant" "$G" batch "$tmp/state.txt" --logs "$tmp/statelogs"
check "... the second renders as its own process" "$TESTTOOL" same "$tmp/ref-1.exr" "$tmp/v-2.exr"
check_fails "no batch file: a usage error" 2 "$G" batch
check_fails "a missing batch file" 1 "$G" batch "$tmp/none.txt"
check "... named" grep -q "none.txt: cannot read" "$tmp/last"
check "batch --help" sh -c "'$G' batch --help | grep -q 'usage: gonio batch'"
finish
