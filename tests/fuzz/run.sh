#!/usr/bin/env bash
# run.sh TARGET...: a bounded libFuzzer run of each target (make fuzz-run): FUZZ_TIME seconds
# each (default 60), seeded in place from scenes/, tests/fuzz/seeds (what the sample models
# lack: a skinned and morphed scene, sparse targets, animated weights), $GONIO_ASSETS (sample
# models, glTF-Validator's invalid files), from EXRs that $GONIO writes here, every
# compression, scanline and tiled, from WebP and KTX2 textures written here ($TESTTOOL
# ktx2, cwebp), and from image-based lights written here. New inputs and crash files go to a temporary folder, kept and named on a crash:
# minimise one (TARGET -minimize_crash=1 FILE), fix the bug, and add the small file to
# tests/fuzz/regress (tests/regress/fuzz.sh replays them in make test).
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
GONIO=$(realpath "${GONIO:-build/release/gonio}")
TESTTOOL=$(realpath "${TESTTOOL:-$(dirname "$GONIO")/testtool}")
A=${GONIO_ASSETS:-$root/../shared/assets}
T=${FUZZ_TIME:-60}
tmp=$(mktemp -d)
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:quarantine_size_mb=16"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)}

# Seeds are symbolic links to the files where they are (libFuzzer follows them).
mkdir -p "$tmp/seed-scene" "$tmp/seed-exr" "$tmp/seed-merge"
n=0
link() { ln -s "$(realpath "$2")" "$1/$n-$(basename "$2")"; n=$((n + 1)); }
for f in scenes/*.gltf tests/fuzz/seeds/*; do link "$tmp/seed-scene" "$f"; done
if [ -d "$A" ]; then
    while IFS= read -r f; do link "$tmp/seed-scene" "$f"; done < <(
        find "$A/gltf" "$A/invalid-gltf" "$A/asset-generator" \( -name '*.gltf' -size -64k \) -o \( -name '*.glb' -size -256k \) 2>/dev/null)
else
    echo "note: $A is absent: the scene fuzzer starts from scenes/ only"
fi
# instances: shared meshes, EXT_mesh_gpu_instancing (floats, normalized shorts, wrong ones)
if python3 tests/tool/instances.py "$tmp/instances" >/dev/null 2>&1; then
    for f in "$tmp"/instances/*.gltf; do link "$tmp/seed-scene" "$f"; done
fi
# skins, morph targets and instancing under attack (tests/tool/attacks.py)
if python3 tests/tool/attacks.py "$tmp/attacks" >/dev/null 2>&1; then
    for f in "$tmp"/attacks/*.gltf; do link "$tmp/seed-scene" "$f"; done
fi
# image-based lights (EXT_lights_image_based): a cube map of six embedded 4x4 PNG faces over
# two levels, rotated and scaled, and one whose faces disagree in size
PYTHONPATH=tests/tool python3 - "$tmp/seed-scene" <<'PY' || echo "note: no image-based-light seeds"
import sys
import gltf_fixture as gf
for name, sizes in (("ibl", [4] * 6), ("ibl-mismatched", [4, 4, 2, 4, 8, 4])):
    g = gf.Gltf()
    faces = [g.image(gf.png(n, n, lambda x, y, f=f: (40 * f, 255 - 40 * f, 16 * x + 8 * y), 3)) for f, n in enumerate(sizes)]
    small = [g.image(gf.png(2, 2, lambda x, y, f=f: (40 * f, 90, 30), 3)) for f in range(6)]
    g.extend(g.doc, "EXT_lights_image_based", lights=[{"rotation": [0, 0.7071068, 0, 0.7071068], "intensity": 1.5,
             "irradianceCoefficients": [[0.1, 0.2, 0.3]] * 9, "specularImageSize": 4,
             "specularImages": [faces, small]}])
    g.scene([g.node(mesh=g.mesh(g.primitive([0, 0, 0, 1, 0, 0, 0, 1, 0])))], extensions={"EXT_lights_image_based": {"light": 0}})
    g.write(f"{sys.argv[1]}/{name}.gltf")
PY
# Textures: a WebP by cwebp and a KTX2 of each Basis Universal mode by testtool ktx2, as GLBs
# that use them (tests/tool/gltf_fixture.py textured-glb) for the scene fuzzer, and bare for
# fuzz_image in its layout: a format byte (1 KTX2, 0 WebP), then the file past its 12-byte
# signature.
mkdir -p "$tmp/tex" "$tmp/seed-image"
PYTHONPATH=tests/tool python3 -c 'import sys, gltf_fixture as gf
open(sys.argv[1], "wb").write(gf.png(8, 8, lambda i, j: (40 + 60 * (i // 2), 40 + 60 * (j // 2), 30 * i, 255 - 20 * j)))' "$tmp/tex/tex.png"
if command -v cwebp >/dev/null; then
    cwebp -quiet -lossless "$tmp/tex/tex.png" -o "$tmp/tex/lossless.webp"
    cwebp -quiet -q 80 "$tmp/tex/tex.png" -o "$tmp/tex/lossy.webp"
else
    echo "note: cwebp is absent: no WebP seeds"
fi
for m in etc1s uastc uastc-zstd; do
    "$TESTTOOL" ktx2 $m "$tmp/tex/tex.png" "$tmp/tex/$m.ktx2" >/dev/null 2>&1 || { echo "note: no KTX2 seeds (testtool ktx2: no Basis Universal)"; break; }
done
for f in "$tmp"/tex/*.webp "$tmp"/tex/*.ktx2; do
    [ -f "$f" ] || continue
    b=$(basename "$f")
    python3 tests/tool/gltf_fixture.py textured-glb "$tmp/seed-scene/tex-$b.glb" "$f"
    python3 tests/tool/gltf_fixture.py textured-glb "$tmp/seed-scene/tex-$b-fallback.glb" "$f" "$tmp/tex/tex.png"
    python3 -c 'import sys; d = open(sys.argv[1], "rb").read(); open(sys.argv[2], "wb").write(bytes([sys.argv[1].endswith(".ktx2")]) + d[12:])' \
        "$f" "$tmp/seed-image/$b"
done
for c in none rle zips zip piz pxr24 b44 b44a; do
    "$GONIO" render scenes/cornell.gltf -o "$tmp/seed-exr/$c.exr" --size 19x13 --spp 1 --quiet --compression $c --aov normal,depth
    "$GONIO" render scenes/cornell.gltf -o "$tmp/seed-exr/$c-half.exr" --size 19x13 --spp 1 --quiet --compression $c --half
    if command -v exrmaketiled >/dev/null; then
        exrmaketiled -z $c -t 8 8 "$tmp/seed-exr/$c-half.exr" "$tmp/seed-exr/$c-tiled.exr" >/dev/null 2>&1 # no zips: tiles are zip
    fi
done
# Resumable partials (sum.* channels) and tile sets for merge: a merge seed is two EXRs, a
# 4-byte little-endian length then the first file, then the second (tests/fuzz/fuzz_merge.c).
P="scenes/cornell.gltf --size 12x8 --spp 2 --quiet"
"$GONIO" render $P -o "$tmp/seed-exr/partial.exr" --resumable --aov normal,albedo,depth,variance
"$GONIO" render $P -o "$tmp/seed-exr/partial-none.exr" --resumable --compression none
"$GONIO" render $P -o "$tmp/t-left.exr" --crop 0,0,6,8 --compression none
"$GONIO" render $P -o "$tmp/t-right.exr" --crop 6,0,12,8 --compression none
"$GONIO" render $P -o "$tmp/t-seed1.exr" --seed 1 --aov variance
"$GONIO" render $P -o "$tmp/t-seed2.exr" --seed 2 --aov variance
"$GONIO" render $P -o "$tmp/t-part.exr" --seed 3 --resumable
pair() { python3 -c 'import struct, sys; a = open(sys.argv[1], "rb").read(); b = open(sys.argv[2], "rb").read()
open(sys.argv[3], "wb").write(struct.pack("<I", len(a)) + a + b)' "$1" "$2" "$3"; }
pair "$tmp/t-left.exr" "$tmp/t-right.exr" "$tmp/seed-merge/tiles"
pair "$tmp/t-seed1.exr" "$tmp/t-seed2.exr" "$tmp/seed-merge/seeds"
pair "$tmp/t-part.exr" "$tmp/t-seed1.exr" "$tmp/seed-merge/partial"
echo "seeds: $(ls "$tmp/seed-scene" | wc -l) scenes, $(ls "$tmp/seed-exr" | wc -l) EXRs, $(ls "$tmp/seed-merge" | wc -l) merges, $(ls "$tmp/seed-image" | wc -l) images"

failed=0
for f in "$@"; do
    t=$(basename "$f")
    case $t in *scene*) seeds=$tmp/seed-scene; len=65536 ;; *merge*) seeds=$tmp/seed-merge; len=32768 ;;
        *image*) seeds=$tmp/seed-image; len=16384 ;;
        *) seeds=$tmp/seed-exr; len=16384 ;; esac
    mkdir -p "$tmp/corpus-$t"
    "$f" "$tmp/corpus-$t" "$seeds" -max_total_time="$T" -max_len=$len -timeout=10 -rss_limit_mb=2048 \
        -artifact_prefix="$tmp/crash-$t-" -print_final_stats=1 >"$tmp/$t.log" 2>&1
    rc=$?
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$tmp/$t.log")
    secs=$(sed -n 's/^stat::.*time.*: *//p' "$tmp/$t.log" | head -n 1)
    crashes=$(ls "$tmp" | grep -c "^crash-$t-")
    echo "$t: ${execs:-?} executions in ${T} s, corpus $(ls "$tmp/corpus-$t" | wc -l) new inputs, $crashes crash file(s), exit $rc"
    if [ "$rc" != 0 ] || [ "$crashes" != 0 ]; then
        failed=1
        grep -m 1 -A 12 "ERROR\|runtime error\|deadly signal" "$tmp/$t.log"
        ls "$tmp"/crash-"$t"-* 2>/dev/null
    fi
done
if [ "$failed" = 0 ]; then
    rm -rf "$tmp"
else
    echo "fuzz: FAILED; logs and crash inputs kept in $tmp"
fi
exit $failed
