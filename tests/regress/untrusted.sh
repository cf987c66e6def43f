#!/usr/bin/env bash
# untrusted.sh: files an attacker or a careless user controls. Outputs are created
# exclusively and never written through a name someone else made (src/core/util.h); inputs
# are regular files, read without blocking on a FIFO; a resumed or merged render trusts only
# what a render writes (types, finite sums, sample counts, windows); --frames patterns are
# checked before any work; text from files is printed with control characters escaped.
# Damaged EXRs are made by tests/tool/exrtool.py, a Python reader and writer of its own.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
X="python3 $(dirname "$0")/../tool/exrtool.py"
command -v python3 >/dev/null || skip_all "python3 is needed to write the damaged files"
S=scenes/cornell.gltf
R="--size 16x16 --quiet"

# ---- outputs: the temporary file ---------------------------------------------------------
# The attack: a symbolic link at the temporary name a gonio of a known PID would use
# (.NAME.tmp-PID, the old fixed name). `exec` keeps the shell's PID for gonio.
O=$tmp/outputs
mkdir -p "$O"
echo victim > "$tmp/victim"
chmod 600 "$tmp/victim"
check "a link at the old temporary name does not redirect the output" sh -c \
    "ln -s '$tmp/victim' '$O/.a.exr.tmp-'\$\$ && exec '$G' render $S -o '$O/a.exr' $R --spp 1"
check "... the victim is untouched" sh -c "grep -qx victim '$tmp/victim' && test \"\$(stat -c %a '$tmp/victim')\" = 600"
check "... and the output is a regular file, not the link" sh -c "test -f '$O/a.exr' && test ! -L '$O/a.exr'"
check "... which is an EXR" "$G" diff "$O/a.exr" "$O/a.exr"
check "the PNG writer too" sh -c \
    "ln -s '$tmp/victim' '$O/.a.png.tmp-'\$\$ && exec '$G' render $S -o '$O/a.png' $R --spp 1"
check "... the victim is untouched" grep -qx victim "$tmp/victim"
check "the glTF writer too" sh -c "ln -s '$tmp/victim' '$O/.c.gltf.tmp-'\$\$ && exec '$G' scene cornell -o '$O/c.gltf'"
check "... the victim is untouched, the output a file" sh -c "grep -qx victim '$tmp/victim' && test -f '$O/c.gltf' -a ! -L '$O/c.gltf'"
check "no temporary file is left behind" sh -c "! ls -A '$O' | grep -q '\.tmp-[0-9]*-'"

# ---- inputs: regular files only, never blocking -------------------------------------------
F=$tmp/fifo
mkdir -p "$F"
mkfifo "$F/scene.gltf" "$F/map.hdr" "$F/map.exr" "$F/part.exr" "$F/view.exr" "$F/tile.exr" "$F/buffer.bin"
# The renders the sections below start from, in one batch (lib.sh, queue): a file for the
# FIFO checks, a resumable partial and its whole render (--resume), halves and a whole (merge).
P=$tmp/resume
M=$tmp/merge
mkdir -p "$P" "$M"
queue ok render $S -o "$F/ok.exr" $R --spp 1 --seed 1
queue part render $S -o "$P/part.exr" $R --spp 4 --resumable --compression none --aov depth,variance
queue one render $S -o "$P/one.exr" $R --spp 8 --aov depth,variance
queue left render $S -o "$M/left.exr" $R --spp 2 --crop 0,0,8,16 --compression none
queue right render $S -o "$M/right.exr" $R --spp 2 --crop 8,0,16,16 --compression none
queue whole render $S -o "$M/whole.exr" $R --spp 2
run_queue
for id in ok part one left right whole; do check_queued "the render '$id' the checks start from" 0 $id; done
fifo_refused() { # fifo_refused DESCRIPTION COMMAND...: exit 1 at once, naming the FIFO
    local what=$1 want=1; shift
    case "$*" in *--camera*) want=2 ;; esac # an option's value: a usage error, as a missing file is
    check_fails "$what" $want timeout 20 "$@"
    check "... saying it is a FIFO ($what)" grep -q "is a FIFO" "$tmp/last"
}
fifo_refused "a FIFO as the scene" "$G" render "$F/scene.gltf" -o "$F/x.exr" $R
fifo_refused "gonio info on a FIFO" "$G" info "$F/scene.gltf"
fifo_refused "--env a FIFO (.hdr)" "$G" render $S -o "$F/x.exr" $R --env "$F/map.hdr"
fifo_refused "--env a FIFO (.exr)" "$G" render $S -o "$F/x.exr" $R --env "$F/map.exr"
fifo_refused "--resume a FIFO" "$G" render $S -o "$F/x.exr" $R --spp 2 --resume "$F/part.exr"
fifo_refused "--camera a FIFO" "$G" render $S -o "$F/x.exr" $R --camera "$F/view.exr"
fifo_refused "merge of a FIFO" "$G" merge "$F/ok.exr" "$F/tile.exr" -o "$F/x.exr"
fifo_refused "diff of a FIFO" "$G" diff "$F/ok.exr" "$F/tile.exr"
python3 - "$F" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf()  # a triangle whose buffer is the FIFO buffer.bin
g.scene([g.node(mesh=g.mesh(g.primitive([0, 0, 0, 1, 0, 0, 0, 1, 0])))], default=False)
g.write(sys.argv[1] + "/buffer.gltf", uri="buffer.bin")
PY
check_fails "a FIFO as a scene's buffer" 1 timeout 20 "$G" info "$F/buffer.gltf"
check "... is not a regular file" grep -q "buffer.bin' is not a regular file" "$tmp/last"
check "no output was written" test ! -e "$F/x.exr"

# ---- --resume: only what a render writes ----------------------------------------------------
# resumed ID PARTIAL DESCRIPTION: --resume PARTIAL to 8 spp gives the one render's file,
# bit for bit (queued, checked once the queue has run)
resumed() {
    queue "$1" render $S -o "$P/$1.exr" $R --spp 8 --resume "$2" --aov depth,variance
    after_queue resumed_checks "$1" "$3"
}
resumed_checks() {
    check_queued "$2: renders" 0 "$1"
    check "$2" "$G" diff "$P/$1.exr" "$P/one.exr" --max-error 0
}
resumed full "$P/part.exr" "an untouched partial resumes to the one render, bit for bit"
check "exrtool copies the partial" $X attr "$P/part.exr" "$P/copy.exr" gonio:note string x
resumed full2 "$P/copy.exr" "... through exrtool's own writer too (it reads and writes the file faithfully)"
# refused NAME DESCRIPTION GREP: --resume $P/NAME.exr fails naming the problem, writes
# nothing (queued: lib.sh, queue; checked once the queue has run)
refused() {
    queue "$1" render $S -o "$P/$1-out.exr" $R --spp 8 --resume "$P/$1.exr" --aov depth,variance
    after_queue refused_checks "$@"
}
refused_checks() {
    check_queued "$2" 1 "$1"
    check "... saying: $3" grep -q -- "$3" "$tmp/last"
    check "... writing nothing" test ! -e "$P/$1-out.exr"
}
for v in nan inf -inf; do
    $X poke "$P/part.exr" "$P/$v.exr" sum.R 3 4 $v
    refused $v "a sum of $v" "channel 'sum.R' at pixel (3, 4) is $v: not finite"
done
$X poke "$P/part.exr" "$P/sq.exr" sum2.G 5 5 nan
refused sq "a square sum of NaN" "channel 'sum2.G' at pixel (5, 5) is nan"
$X retype "$P/part.exr" "$P/uint.exr" sum.G uint
refused uint "a sum channel stored as uint (its floats read as integers near 1e9)" "'sum.G' is stored as unsigned int"
$X retype "$P/part.exr" "$P/half.exr" sum.B half
refused half "a sum channel stored as half" "'sum.B' is stored as 16-bit half"
$X attr "$P/part.exr" "$P/spp6.exr" gonio:spp int 6
refused spp6 "a header spp the sums contradict (6 for 4)" "'sum.N' at pixel (0, 0) is 4: the header's gonio:spp is 6"
$X attr "$P/part.exr" "$P/spp2.exr" gonio:spp int 2
refused spp2 "a header spp of 2 for sums of 4" "gonio:spp"
$X poke "$P/part.exr" "$P/cov.exr" sum.A 2 2 2.5
refused cov "a coverage of 2.5 samples" "'sum.A' at pixel (2, 2) is 2.5: not a whole number of samples"
$X poke "$P/part.exr" "$P/neg.exr" sum.R 1 1 -1
refused neg "a negative radiance sum (path)" "'sum.R' at pixel (1, 1) is -1: negative"
$X poke "$P/part.exr" "$P/depth.exr" sum.depth.Z 1 1 -3
refused depth "a negative depth sum" "'sum.depth.Z' at pixel (1, 1) is -3: negative"
$X window "$P/part.exr" "$P/moved.exr" 8 0
refused moved "a partial whose data window is not the render's" "are not this render's region"
run_queue

# ---- merge: only tiles of one render --------------------------------------------------------
check "two halves merge into the whole render" sh -c \
    "'$G' merge '$M/left.exr' '$M/right.exr' -o '$M/m.exr' && '$G' diff '$M/m.exr' '$M/whole.exr' --max-error 0"
$X window "$M/right.exr" "$M/outside.exr" 8 0
check_fails "a tile whose data window lies outside the display window is refused" 1 \
    "$G" merge "$M/left.exr" "$M/outside.exr" -o "$M/x.exr"
check "... saying so" grep -q "outside.exr: its data window (16,0)+8x16 lies outside its 16x16 display window" "$tmp/last"
check "... writing nothing" test ! -e "$M/x.exr"
$X poke "$M/right.exr" "$M/nan.exr" G 2 3 nan
check_fails "a NaN pixel in an input is refused" 1 "$G" merge "$M/left.exr" "$M/nan.exr" -o "$M/x.exr"
check "... naming the channel and pixel" grep -q "nan.exr: channel 'G' has 1 NaN or infinite value(s), the first at pixel (10, 3)" "$tmp/last"
$X poke "$M/left.exr" "$M/inf.exr" R 0 0 inf
check_fails "an infinite pixel too" 1 "$G" merge "$M/inf.exr" "$M/right.exr" -o "$M/x.exr"
for k in 1 2 3 4 5 6; do cp "$M/whole.exr" "$M/same$k.exr"; done
check_fails "merge --force of six copies of one seed" 0 "$G" merge "$M"/same?.exr -o "$M/forced.exr" --force
check "... warns once, with the count (15 pairs)" sh -c \
    "test \"\$(grep -c warning '$tmp/last')\" = 1 && grep -q '15 pair(s) of overlapping inputs share a seed' '$tmp/last'"

# ---- --frames patterns: checked before any work ---------------------------------------------
for p in '%99999999999d' '%2147483647d' '%17d'; do
    check_fails "--frames -o f_$p.exr is refused" 2 timeout 10 "$G" render $S -o "$tmp/f_$p.exr" --frames 0-1 $R
    check "... the width is too large (at most 16)" grep -q "the width of the frame number is too large (at most 16)" "$tmp/last"
done
check_fails "--frames -o with a %s is refused" 2 "$G" render $S -o "$tmp/f_%s.exr" --frames 0-1 $R
check_fails "--frames -o whose names lose the extension is refused" 2 "$G" render $S -o "$tmp/f.exr%d" --frames 0-1 $R
check "nothing was written" sh -c "! ls '$tmp' | grep -q '^f_'"
check "a %04d pattern renders every frame" "$G" render $S -o "$tmp/fr_%04d.exr" --frames 2-3 $R --spp 1
check "... to its own file" test -f "$tmp/fr_0002.exr" -a -f "$tmp/fr_0003.exr"

# ---- range errors name the bound -------------------------------------------------------------
check_fails "--fps 1e7 is out of range" 2 "$G" render $S -o "$tmp/x.exr" --fps 1e7
check "... naming it" grep -q "out of range: must be in (0, 1000000\]" "$tmp/last"
check_fails "--at 1e10 is out of range" 2 "$G" render $S -o "$tmp/x.exr" --at 1e10
check "... naming it" grep -q "out of range: must be in \[0, 1000000000\]" "$tmp/last"

# ---- text from files: control characters escaped --------------------------------------------
python3 - "$tmp/esc.gltf" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf.load("scenes/cornell.gltf")
for m in g.doc["materials"]:
    if m.get("name") == "light":  # the emitter: gonio info names it
        m["name"] = "light\x1b[2J\x1b]0;owned\x07\nforged line"
g.variants("v\x1b[31m")
g.write(sys.argv[1])
PY
esc=$(printf '\033')
check_fails "gonio info on names with escape sequences" 0 "$G" info "$tmp/esc.gltf"
check "... prints them escaped" sh -c "! grep -q '$esc' '$tmp/last' && grep -qF 'light\\x1b[2J\\x1b]0;owned\\x07\\x0aforged line (2)' '$tmp/last' && grep -qF 'v\\x1b[31m' '$tmp/last'"
check_fails "an unknown --variant with an escape sequence" 1 "$G" render "$tmp/esc.gltf" -o "$tmp/x.exr" $R \
    --variant "$(printf 'x\033[2J')"
check "... is printed escaped" sh -c "! grep -q '$esc' '$tmp/last' && grep -qF 'x\\x1b[2J' '$tmp/last'"

# ---- the loader: variants, compressed-mesh bindings, animation keys ---------------------------
L=$tmp/loader
mkdir -p "$L"
# gonio's own Cornell box, shared with gltf_ext.sh (lib.sh, fixture)
cornell=$(fixture cornell.gltf "$G" scene cornell -o {})
# bad_scene NAME DESCRIPTION GREP: gonio info L/NAME.gltf fails naming the JSON path and value
bad_scene() {
    check_fails "$2" 1 "$G" info "$L/$1.gltf"
    check "... naming it: $3" grep -qF -- "$3" "$tmp/last"
}
python3 - "$L" "$cornell" <<'PY'
import sys
import gltf_fixture as gf
L = sys.argv[1]
def variants(name, mappings, names=("a", "b")):
    g = gf.Gltf.load(sys.argv[2])
    g.variants(*names)
    g.extend(g.doc["meshes"][3]["primitives"][0], "KHR_materials_variants", mappings=mappings)
    g.write(f"{L}/{name}.gltf")
variants("var-ok", [{"material": 2, "variants": [1]}, {"material": 1, "variants": [0]}])
variants("var-range", [{"material": 2, "variants": [5]}])
variants("var-negative", [{"material": 2, "variants": [-1]}])
variants("var-material-fraction", [{"material": 1.5, "variants": [0]}])
variants("var-material-range", [{"material": 99, "variants": [1]}])
variants("var-twice", [{"material": 2, "variants": [0, 1]}, {"material": 1, "variants": [1]}])
variants("var-empty", [{"material": 2, "variants": []}])
PY
check "variant mappings as the extension defines them load" "$G" info "$L/var-ok.gltf"
bad_scene var-range "a mapping's variant index out of range" \
    "meshes[3].primitives[0].extensions.KHR_materials_variants.mappings[0].variants[0]: 5 does not exist (KHR_materials_variants variants has 2 entries)"
bad_scene var-negative "a negative variant index" "mappings[0].variants[0]: -1 is not a valid index (negative)"
bad_scene var-material-fraction "a material index of 1.5" "mappings[0].material: 1.5 is not an integer index"
bad_scene var-material-range "a material index beyond the list (an error whichever variant is chosen)" \
    "mappings[0].material: 99 does not exist"
bad_scene var-twice "one variant in two mappings of a primitive" \
    "mappings[1].variants[0]: variant 1 is mapped already, at meshes[3].primitives[0].extensions.KHR_materials_variants.mappings[0].variants[1]"
bad_scene var-empty "a mapping with no variants" "mappings[0].variants: is empty"
check_fails "--variant '' is bad usage" 2 "$G" render "$L/var-ok.gltf" -o "$L/x.exr" $R --variant ""

# Compressed meshes, encoded by the libraries' own encoders (testtool compress).
"$G" teapot --level 2 -o "$L/teapot.gltf"
"$TESTTOOL" compress meshopt "$L/teapot.gltf" "$L/teapot-meshopt.gltf"
"$TESTTOOL" compress draco "$L/teapot.gltf" "$L/teapot-draco.gltf"
python3 - "$L" <<'PY'
import sys
import gltf_fixture as gf
L = sys.argv[1]
meshopt = lambda g: [v for v in g.doc["bufferViews"] if "EXT_meshopt_compression" in v.get("extensions", {})]
# The fallback buffer: no data, and too short for the views that decode into it.
short = gf.Gltf.load(L + "/teapot-meshopt.gltf")
short.doc["buffers"][meshopt(short)[0]["buffer"]] = {"byteLength": 16, "extensions": {"EXT_meshopt_compression": {"fallback": True}}}
short.doc["extensionsRequired"] = sorted(set(short.doc.get("extensionsRequired", []) + ["EXT_meshopt_compression"]))
short.write(L + "/meshopt-short.gltf")
big = gf.Gltf.load(L + "/teapot-meshopt.gltf")
meshopt(big)[0]["extensions"]["EXT_meshopt_compression"]["count"] = 4294967295
big.write(L + "/meshopt-count.gltf")
vec2, short_pos = gf.Gltf.load(L + "/teapot-draco.gltf"), gf.Gltf.load(L + "/teapot-draco.gltf")
pos = vec2.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
a = vec2.doc["accessors"][pos]
a["type"], a["min"], a["max"] = "VEC2", a["min"][:2], a["max"][:2]
vec2.write(L + "/draco-vec2.gltf")
short_pos.doc["accessors"][pos]["componentType"] = gf.SHORT
short_pos.write(L + "/draco-short.gltf")
PY
check "the meshopt and Draco teapots load" sh -c "'$G' info '$L/teapot-meshopt.gltf' && '$G' info '$L/teapot-draco.gltf'"
bad_scene meshopt-short "a meshopt fallback buffer shorter than the views over it" "lie beyond buffers["
bad_scene meshopt-count "a meshopt count of 2^32 - 1" "count 4294967295 x byteStride"
bad_scene draco-vec2 "a 2-component accessor bound to a 3-component Draco attribute" \
    "meshes[0].primitives[0].extensions.KHR_draco_mesh_compression.attributes.POSITION: accessors[0] has 2 components, but Draco attribute 1 has 3"
bad_scene draco-short "short-integer Draco positions (without KHR_mesh_quantization)" \
    "attributes.POSITION: accessors[0] declares component type 5122, but Draco attribute 1 decodes to floats"
A=${GONIO_ASSETS:-}/gltf/RiggedSimple/glTF/RiggedSimple.gltf
if [ -f "$A" ]; then
    # Draco keeps JOINTS_0 unsigned short: a compressed skinned mesh loads like the original.
    python3 - "$A" "$L/rigged.gltf" <<'PY'
import os, sys
import gltf_fixture as gf
g = gf.Gltf.load(sys.argv[1])
for b in g.doc["buffers"]:
    b["uri"] = gf.data_uri(open(os.path.join(os.path.dirname(sys.argv[1]), b["uri"]), "rb").read())
g.write(sys.argv[2])
PY
    check "RiggedSimple (unsigned short joints) compresses with Draco" "$TESTTOOL" compress draco "$L/rigged.gltf" "$L/rigged-draco.gltf"
    check "... and loads" "$G" info "$L/rigged-draco.gltf"
    check "... rendering as the original does" sh -c "'$G' render '$L/rigged.gltf' -o '$L/r0.exr' $R --spp 2 && \
        '$G' render '$L/rigged-draco.gltf' -o '$L/r1.exr' $R --spp 2 && '$TESTTOOL' same '$L/r0.exr' '$L/r1.exr'"
else
    echo "  note: $A is absent: the Draco skinned-mesh check is skipped"
fi

# Animation samplers, checked whether or not --at samples them.
python3 - "$L" "$cornell" <<'PY'
import sys
import gltf_fixture as gf
L = sys.argv[1]
def anim(name, times, values, comp=gf.FLOAT, normalized=False, path="rotation", vtype="VEC4"):
    g = gf.Gltf.load(sys.argv[2])  # its views in a buffer of their own, after the box's
    key = g.accessor(times, "SCALAR", bounds=True)
    g.add("animations", {"samplers": [{"input": key, "output": g.accessor(values, vtype, comp, normalized=normalized)}],
                         "channels": [{"sampler": 0, "target": {"node": 1, "path": path}}]})
    g.write(f"{L}/{name}.gltf")
q = [0, 0, 0, 1]
anim("anim-ok", [0, 1], q + q)
anim("anim-equal", [0, 1, 1], q + q + q)
anim("anim-short-rot", [0, 1], [0, 0, 0, 32767] * 2, comp=gf.SHORT)
anim("anim-short-rot-n", [0, 1], [0, 0, 0, 32767] * 2, comp=gf.SHORT, normalized=True)
PY
check "an animation as the spec allows loads" "$G" info "$L/anim-ok.gltf"
check "normalized short rotations load" "$G" info "$L/anim-short-rot-n.gltf"
bad_scene anim-equal "equal key times" "animations[0].samplers[0].input: key 2 at 1 s is not after the key before it"
bad_scene anim-short-rot "non-normalized short rotations" \
    "animations[0].samplers[0].output: accessor"
check "... naming the rule" grep -qF "is not allowed for 'rotation' (float, or normalized byte or short)" "$tmp/last"
finish
