#!/usr/bin/env bash
# hostile.sh: inputs that try to make gonio read what it should not or misread what it
# reads. A scene reads only regular files under its own folder (src/scene/scene.h); errors name
# the URI and reveal nothing about the file refused. Scenes are glTF JSON written by Python.
# Also: command-line values parsed strictly, and what an output path may be (src/core/util.h).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to write the test scenes"
D=$tmp/scenes
mkdir -p "$D/a/b" "$tmp/cwd"
python3 - "$tmp" <<'PY'
import sys
import gltf_fixture as gf
t = sys.argv[1]
# a triangle, its buffer the file the case names
g = gf.Gltf()
g.scene([g.node(mesh=g.mesh(g.primitive([0, 0, 0, 1, 0, 0, 0, 1, 0])))])
blob = bytes(g.data)
for f in ("secret.bin", "scenes/a/b/tri.bin", "cwd/only-here.bin"):
    open(f"{t}/{f}", "wb").write(blob)
open(f"{t}/big-secret.bin", "wb").write(blob * 70)  # 2520 bytes: a size an error must not tell
cases = {"ok": "tri.bin", "up": "../../../secret.bin", "pct": "%2e%2e/%2e%2e/%2e%2e/secret.bin",
         "abs": f"{t}/secret.bin", "dot": ".", "dotdot": "..", "root": "/", "link": "link.bin",
         "cwd": "only-here.bin", "size": "../../../big-secret.bin"}
for name, uri in cases.items():
    g.doc["buffers"][0]["byteLength"] = 12 if name == "size" else 36
    g.write(f"{t}/scenes/a/b/{name}.gltf", uri=uri)
PY
ln -sf "$tmp/secret.bin" "$D/a/b/link.bin"
B=$D/a/b
# A camera aspect ratio from the file (0.004), for the render of the longer side's 512 below.
python3 - "$B/ok.gltf" "$B/thin.gltf" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf.load(sys.argv[1])
g.doc["scenes"][0]["nodes"].append(g.node(camera=g.perspective(0.5, 0.1, aspect=0.004), translation=[0.3, 0.3, 3]))
g.write(sys.argv[2])
PY
# A light and an emitter of 1e39, for the renders of finite pixels below.
python3 - "$B/ok.gltf" "$B/bright.gltf" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf.load(sys.argv[1])
g.doc["scenes"][0]["nodes"].append(g.node(light=g.light("point", intensity=1e39), translation=[0.2, 0.2, 1]))
m = {"emissiveFactor": [1, 1, 1]}
g.extend(m, "KHR_materials_emissive_strength", emissiveStrength=1e39)
g.doc["meshes"][0]["primitives"][0]["material"] = g.material(m)
g.write(sys.argv[2])
PY
# Outputs (the checks below): an existing file of mode 640, and one of another owner (when
# root), that a render replaces; stale temporary files of a gonio killed while writing.
O=$tmp/outputs
mkdir -p "$O"
R="--size 8x8 --spp 1 --quiet"
echo old > "$O/mode.exr"
chmod 640 "$O/mode.exr"
owner=0
if [ "$(id -u)" = 0 ] && id nobody >/dev/null 2>&1; then
    owner=1
    echo old > "$O/owner.exr"
    chmod 640 "$O/owner.exr"
    chown nobody "$O/owner.exr"
fi
dead=$(sh -c 'echo $$')
echo half > "$O/.out.exr.tmp-$dead-a1b2c3"
echo live > "$O/.out.exr.tmp-$$-a1b2c3"
echo other > "$O/.other.exr.tmp-$dead-a1b2c3"

# ---- the renders, queued (lib.sh: queue): the script's renders run in one batch, whose
# results the checks below read; commands refused before any work, `gonio info` and
# `gonio merge` stay processes of their own (cheap: no device).
queue up render "$B/up.gltf" --allow-outside-files -o "$tmp/up.exr" --size 8x8 --spp 1 --quiet
queue thin render "$B/thin.gltf" -o "$tmp/thin.exr" --spp 1 --quiet
for sd in 3000000000 3000000001; do
    queue seed-$sd render "$B/ok.gltf" -o "$tmp/seed-$sd.exr" --size 8x8 --spp 1 --seed $sd --quiet
done
for m in path phong; do
    queue bright-$m render "$B/bright.gltf" -o "$tmp/bright-$m.exr" --mode $m --size 16x16 --spp 2 --quiet
done
queue v render "$B/ok.gltf" -o "$tmp/v.exr" --size 16x16 --spp 1 --fov 30 --env 0.5,1,0 --quiet
queue v-brdf render "$B/ok.gltf" -o "$tmp/v.exr" --size 8x8 --spp 1 --brdf ggx:alpha=0.3:diffuse=0.2,0.4,0.6 --quiet
queue mode render "$B/ok.gltf" -o "$O/mode.exr" $R
[ $owner = 1 ] && queue owner render "$B/ok.gltf" -o "$O/owner.exr" $R
queue stale render "$B/ok.gltf" -o "$O/out.exr" $R
queue a render "$B/ok.gltf" -o "$O/a.exr" $R --seed 1
queue b render "$B/ok.gltf" -o "$O/b.exr" $R --seed 2
run_queue

check "a buffer beside the scene loads" "$G" info "$B/ok.gltf"
for c in up pct abs link; do
    check_fails "$c: a buffer outside the scene's folder is refused" 1 "$G" info "$B/$c.gltf"
    check "$c: the error names the scene" grep -q "$c.gltf" "$tmp/last"
done
check "the error says why" grep -q "outside the scene's folder" "$tmp/last"
for c in dot dotdot root; do
    check_fails "$c: a URI naming a directory is an error" 1 "$G" info "$B/$c.gltf"
    check "$c: no 'out of memory'" sh -c "! grep -q 'out of memory' '$tmp/last'"
done
# tinygltf would fall back to the working directory for a file missing beside the scene.
check_fails "cwd: a file only in the working directory is not read" 1 sh -c "cd '$tmp/cwd' && '$G' info '$B/cwd.gltf'"
check_fails "size: a wrong byteLength on an outside file is refused" 1 "$G" info "$B/size.gltf"
check "... without telling the file's size" sh -c "! grep -q 2520 '$tmp/last'"
check "--allow-outside-files reads it" "$G" info "$B/up.gltf" --allow-outside-files
check_queued "render --allow-outside-files too" 0 up
check_fails "render refuses it by default" 1 "$G" render "$B/up.gltf" -o "$tmp/up2.exr" --size 8x8 --spp 1 --quiet
check "... and writes nothing" test ! -e "$tmp/up2.exr"
check_fails "a directory as the scene is an error" 1 "$G" info "$tmp"
check "... naming it, not 'out of memory'" sh -c "grep -q 'is a directory; gonio reads only regular files' '$tmp/last' && ! grep -q 'out of memory' '$tmp/last'"

# A camera aspect ratio from the file suggests the size, within the longer side's 512.
check_queued "a camera aspect of 0.004 renders" 0 thin
check "... at most 512 pixels on its longer side" sh -c "exrheader '$tmp/thin.exr' | grep -q 'dataWindow.*(0 0) - (1 511)'"

# Amplification: a few hundred bytes of JSON must not decode into gigabytes. One accessor of
# 4,000,000 zero positions (no buffer view) drawn by 13 primitives is 17.3 M triangles, over
# SCENE_MAX_TRIANGLES (2^24): refused before anything is read, with the numbers.
python3 - "$B/amplified.gltf" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf()
zeros = g.add("accessors", {"componentType": gf.FLOAT, "count": 4000000, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]})
g.scene([g.node(mesh=g.mesh(*[{"attributes": {"POSITION": zeros}} for _ in range(13)]))])
g.write(sys.argv[1])
PY
check_fails "a 17 M-triangle amplification is refused" 1 "$G" info "$B/amplified.gltf"
check "... with the numbers" grep -q "scene too large: .* the limit is 16777216" "$tmp/last"
# Sharing is legitimate (one mesh drawn by many nodes is instancing), so the same accessor
# drawn by 16 nodes is not refused by size: what keeps it cheap is that every step stays
# O(n log n) on coincident triangles. A mesh all of whose 1.33 M triangles sit at one point is
# dropped with one warning before anything is built of it; 150,000 copies of one triangle
# (every edge shared by all of them, a 0.9 MB file) load. Either in seconds, not minutes.
python3 - "$B" <<'PY'
import sys
import gltf_fixture as gf
b = sys.argv[1]
g = gf.Gltf()
zeros = g.add("accessors", {"componentType": gf.FLOAT, "count": 3999999, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]})
point = g.mesh({"attributes": {"POSITION": zeros}})
g.scene([g.node(mesh=point) for _ in range(16)])
g.write(b + "/point.gltf")
g = gf.Gltf()
n = 150000
tri = g.accessor([0, 0, 0, 1, 0, 0, 0, 1, 0], "VEC3", bounds=True)
idx = g.accessor(gf.pack(gf.UNSIGNED_SHORT, [0, 1, 2] * n), "SCALAR", component=gf.UNSIGNED_SHORT, count=3 * n)
g.scene([g.node(mesh=g.mesh({"attributes": {"POSITION": tri}, "indices": idx}))])
g.write(b + "/stacked.gltf", bin="stacked.bin")
PY
check_fails "16 nodes drawing 1.33 M triangles at one point: no triangles left" 1 timeout 20 "$G" info "$B/point.gltf"
check "... said once, naming the primitive" test "$(grep -c 'mesh 0 primitive 0: all 1333333 triangles have zero area (skipped)' "$tmp/last")" = 1
check "150,000 copies of one triangle load" timeout 20 "$G" info "$B/stacked.gltf"
# The loaders of skins, morph targets and instancing under attack (tests/tool/attacks.py:
# singular, non-finite and huge inverse bind matrices, weights that do not sum to one, joints
# outside the tree, in a loop or missing, 70,000 joints, 5,000 targets, weights that carry
# positions to infinity, 10^9 instances asked directly or by sharing, counts that disagree):
# each gives its exit status and its message, in seconds, and no other warning.
python3 tests/tool/attacks.py "$tmp/attacks" || fail "attacks.py"
while read -r attack status message; do
    timeout 20 "$G" info "$tmp/attacks/$attack.gltf" >/dev/null 2>"$tmp/attack.err"
    got=$?
    check "attack $attack: exit $status (got $got)" test "$got" = "$status"
    if [ "$message" = - ]; then
        check "... and no warning" sh -c "! grep -q 'warning\|error' '$tmp/attack.err'"
    else
        check "... saying '$message'" grep -qF -- "$message" "$tmp/attack.err"
    fi
done <"$tmp/attacks/expect.txt"
# Images: the same bytes are decoded once and count once against SCENE_MAX_TEXELS (2^28).
# A 16384 x 4096 grey PNG is 67 M texels: listed 8 times it loads, 5 different ones do not.
python3 - "$B" <<'PY'
import sys
import gltf_fixture as gf
b = sys.argv[1]
for k in range(5):
    open(f"{b}/big{k}.png", "wb").write(gf.png(16384, 4096, bytes([40 * k]) * (16384 * 4096), channels=1))
same, different = gf.Gltf.load(b + "/ok.gltf"), gf.Gltf.load(b + "/ok.gltf")
for _ in range(8):
    same.image(uri="big0.png")
for k in range(5):
    different.image(uri=f"big{k}.png")
same.write(b + "/same-images.gltf")
different.write(b + "/many-images.gltf")
PY
check "one 67 M-texel image listed 8 times loads (decoded once)" "$G" info "$B/same-images.gltf"
check_fails "5 different ones (335 M texels) are refused" 1 "$G" info "$B/many-images.gltf"
check "... with the numbers" grep -q "images too large: 335544320 texels with image 4 (16384x4096), the limit is 268435456" "$tmp/last"

# A scene opened through a symlinked folder reads its own files; so does a "./" URI of a
# scene named without a folder.
ln -sfn "$B" "$tmp/linked"
check "a scene in a symlinked folder loads its buffer" "$G" info "$tmp/linked/ok.gltf"
python3 - "$B/ok.gltf" "$B/dotslash.gltf" <<'PY'
import sys
import gltf_fixture as gf
g = gf.Gltf.load(sys.argv[1])
g.doc["buffers"][0]["uri"] = "./tri.bin"
g.write(sys.argv[2])
PY
check "a ./ URI of a scene named without a folder" sh -c "cd '$B' && '$G' info dotslash.gltf"

# Images in a .glb's buffer views count against SCENE_MAX_TEXELS too.
python3 - "$B" <<'PY'
import sys
import gltf_fixture as gf
b = sys.argv[1]
g = gf.Gltf()  # ok.gltf's triangle, and the five images in the binary chunk
g.scene([g.node(mesh=g.mesh(g.primitive([0, 0, 0, 1, 0, 0, 0, 1, 0])))])
for k in range(5):
    g.image(open(f"{b}/big{k}.png", "rb").read(), in_buffer=True)
g.glb(b + "/many-images.glb")
PY
check_fails "5 different 67 M-texel images in a .glb are refused" 1 "$G" info "$B/many-images.glb"
check "... with the numbers" grep -q "images too large: 335544320 texels" "$tmp/last"

# Seeds of 2^31 and above survive the EXR header's signed int: merge still sees a repeat.
for sd in 3000000000 3000000001; do
    check_queued "render --seed $sd" 0 seed-$sd
done
check "the same seed twice" cp "$tmp/seed-3000000000.exr" "$tmp/seed-again.exr"
check_fails "merge refuses seed 3000000000 twice" 1 "$G" merge "$tmp/seed-3000000000.exr" "$tmp/seed-again.exr" -o "$tmp/sm.exr"
check "merge takes 3000000000 and 3000000001" "$G" merge "$tmp/seed-3000000000.exr" "$tmp/seed-3000000001.exr" -o "$tmp/sm.exr"
check "... and lists them" sh -c "exrheader '$tmp/sm.exr' | grep -q 'gonio:seeds (type string): \"3000000000,3000000001\"'"

# bench --generate below what the generator can build was accepted and then aborted.
check_fails "bench --generate 999 is a usage error, not an abort" 2 "$G" bench --generate 999
check "... naming the range" grep -q "1000..50000000" "$tmp/last"

# Huge radiance: clamped or refused, never NaN or Inf pixels.
check_fails "--env 1e38 is refused" 2 "$G" render "$B/ok.gltf" -o "$tmp/x.exr" --env 1e38 --quiet
for m in path phong; do
    check_queued "a light and an emitter of 1e39 render ($m)" 0 bright-$m
    check "... with finite pixels ($m)" sh -c "'$TESTTOOL' stats '$tmp/bright-$m.exr' | grep -q 'nonfinite 0\$'"
done
check "the clamp is a warning naming the value" sh -c "'$G' info '$B/bright.gltf' 2>&1 | grep -q 'intensity 1e+39 is above 1e+09 (clamped)'"
# Command-line values are numbers as typed: no leading space or sign, nothing left over.
for v in " 16x16" "+16x+16" "16x+16" "16x 16" "0x16" "16x16 "; do
    check_fails "--size '$v' is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --size "$v" --quiet
done
check_fails "--spp +4 is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --spp +4 --quiet
check_fails "--spp ' 4' is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --spp " 4" --quiet
check_fails "--fov +30 is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --fov +30 --quiet
check_fails "--env ' 1' is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --env " 1" --quiet
check_fails "--env 0x1p1 is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --env 0x1p1 --quiet
check_queued "--size 16x16 --spp 1 --fov 30 --env 0.5,1,0 still render" 0 v
for v in "ggx:::" "ggx:" "ggx:alpha=0.3:" ":alpha=0.3" "ggx:=1"; do
    check_fails "--brdf '$v' is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --brdf "$v" --quiet
done
check_fails "--brdf ggx:alpha=5 is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --brdf ggx:alpha=5 --quiet
check "... naming the parameter as it was given" sh -c "grep -q 'parameter alpha=5 is out of range' '$tmp/last' && ! grep -q -- '--alpha' '$tmp/last'"
check_fails "--brdf ggx:shininess=5 is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --brdf ggx:shininess=5 --quiet
check "... listing the parameters in the spec's form" sh -c "grep -q 'no parameter shininess; it accepts .*alpha=X' '$tmp/last' && ! grep -q -- '--alpha' '$tmp/last'"
check_fails "--brdf nosuch is bad usage" 2 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --brdf nosuch --quiet
check_queued "--brdf ggx:alpha=0.3:diffuse=0.2,0.4,0.6 renders" 0 v-brdf
check_fails "gonio brdf's own option still says --alpha" 2 "$G" brdf ggx --alpha 5 -o "$tmp/lobe.png"
check "... (--alpha)" grep -q -- "--alpha 5 is out of range" "$tmp/last"
# Under the sanitizers a refused device index must not leak (the driver was unloaded
# before LeakSanitizer could name its allocations).
check_fails "--device 63 is refused cleanly" 1 "$G" render "$B/ok.gltf" -o "$tmp/v.exr" --device 63 --quiet
check "... naming the devices" grep -q "only .* device(s)" "$tmp/last"
# ---- Outputs: a new name or a writable regular file, nothing else (src/core/util.h) ------------
# ($O, mode.exr, owner.exr and the stale temporary files are made above, before the renders)
echo secret > "$O/target.exr"
ln -s target.exr "$O/link.exr"
mkfifo "$O/fifo.exr"
mkdir "$O/dir.exr" "$O/dir.png" "$O/dir.gltf"
check_fails "-o a symbolic link is refused" 1 "$G" render "$B/ok.gltf" -o "$O/link.exr" $R
check "... saying so" grep -q "link.exr: is a symbolic link" "$tmp/last"
check "... and the link and its target stay" sh -c "test -L '$O/link.exr' && grep -q secret '$O/target.exr'"
check_fails "-o a FIFO (a special file) is refused" 1 "$G" render "$B/ok.gltf" -o "$O/fifo.exr" $R
check "... saying so" grep -q "fifo.exr: is not a regular file" "$tmp/last"
check "... and it stays a FIFO" test -p "$O/fifo.exr"
check_fails "-o a directory is refused" 1 "$G" render "$B/ok.gltf" -o "$O/dir.exr" $R
check "... saying so" grep -q "dir.exr: is a directory" "$tmp/last"
check_fails "--png a directory too" 1 "$G" render "$B/ok.gltf" -o "$O/new.exr" --png "$O/dir.png" $R
check "... before writing -o" test ! -e "$O/new.exr"
check_fails "-o in a missing folder is refused" 1 "$G" render "$B/ok.gltf" -o "$O/none/x.exr" $R
check "... naming it" grep -q "none/x.exr: folder '.*none' does not exist" "$tmp/last"
long=$O/$(printf 'd%.0s' $(seq 200))/$(printf 'd%.0s' $(seq 200))
long=$long$long$long$long$long$long$long$long$long$long$long.exr
check_fails "-o longer than PATH_MAX is refused" 1 "$G" render "$B/ok.gltf" -o "$long" $R
check "... with a message" grep -q "output path of [0-9]* characters is too long" "$tmp/last"
check_fails "-o with a 250-character name is refused (its temporary name would not fit)" 1 \
    "$G" render "$B/ok.gltf" -o "$O/$(printf 'n%.0s' $(seq 246)).exr" $R
check "... with a message" grep -q "file name of 250 characters is too long" "$tmp/last"
echo keep > "$O/ro.exr"
chmod 444 "$O/ro.exr"
check_fails "-o a read-only file is refused (for root too)" 1 "$G" render "$B/ok.gltf" -o "$O/ro.exr" $R
check "... saying so, and it stays" sh -c "grep -q 'ro.exr: is read-only' '$tmp/last' && grep -q keep '$O/ro.exr'"
check_queued "-o an existing file replaces it" 0 mode
check "... keeping its mode" test "$(stat -c %a "$O/mode.exr")" = 640
if [ $owner = 1 ]; then
    # owner.exr: another existing file of mode 640, owned by nobody, replaced by root
    owner_kept() { queued_ok owner || { cat "$tmp/last"; return 1; }; test "$(stat -c %U "$O/owner.exr")" = nobody; }
    check "... and its owner (root writing)" owner_kept
fi
# A gonio killed while writing leaves .NAME.tmp-PID-XXXXXX: the next write of NAME removes it
# when that process is gone, and leaves other names and live processes' files alone.
check_queued "a stale temporary file is cleaned up" 0 stale
check "... the dead process's one is gone" test ! -e "$O/.out.exr.tmp-$dead-a1b2c3"
check "... a live process's and another name's stay" test -e "$O/.out.exr.tmp-$$-a1b2c3" -a -e "$O/.other.exr.tmp-$dead-a1b2c3"
# Every command that writes checks the same way, before any work (a.exr and b.exr: rendered above).
check_fails "merge -o a symbolic link is refused" 1 "$G" merge "$O/a.exr" "$O/b.exr" -o "$O/link.exr"
check "... saying so" grep -q "link.exr: is a symbolic link" "$tmp/last"
ln -s target.gltf "$O/link.gltf"
ln -s target.png "$O/link.png"
check_fails "scene -o a symbolic link is refused" 1 "$G" scene cornell -o "$O/link.gltf"
check_fails "teapot -o a directory is refused" 1 "$G" teapot -o "$O/dir.gltf"
check_fails "brdf -o a symbolic link is refused" 1 "$G" brdf ggx --theta 30 -o "$O/link.png"
check "... saying so" grep -q "link.png: is a symbolic link" "$tmp/last"
check "... and no target was written" test ! -e "$O/target.gltf" -a ! -e "$O/target.png"
finish
