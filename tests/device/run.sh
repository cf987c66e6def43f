#!/usr/bin/env bash
# tests/device/run.sh: one call on a machine with a real Vulkan GPU (make device-check):
# builds gonio, lists the devices, picks the first GPU (or DEVICE=N), renders a short
# regression subset on it and prints the benchmarks, in about five minutes:
#   1. the devices, their drivers and whether they have ray queries (gonio devices);
#   2. correctness on the GPU: the Cornell box and the teapot rendered on the GPU and on
#      lavapipe (when present), their means within 2% (gonio diff: at 128x128 and 256 spp
#      the Monte Carlo error of a mean is far below that; a wrong kernel is not);
#      textured, alpha-tested (TransmissionTest's MASK) sample model and an animated frame render with the validation
#      layer on;
#   3. the benchmarks: primary and diffuse Mrays/s and the time to the first pixel (gonio
#      bench) on the Cornell box, a 250k-triangle mesh and DamagedHelmet; paths/s (bench
#      --paths) on the Cornell box and DamagedHelmet.
# Every figure is printed with the device and driver; docs/performance.md takes them with the
# date and this command. Exit 1 when a render or comparison fails; 77 when no GPU is found
# (DEVICE=N forces one, a CPU device included, to try the script here).
set -u
cd "$(dirname "$0")/../.."
make -j"$(nproc)" >/dev/null || { echo "device: the build failed"; exit 1; }
G=build/release/gonio
A=${GONIO_ASSETS:-../shared/assets}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
start=$(date +%s)
stage() { echo "== $* [$(($(date +%s) - start)) s]"; }

stage "devices"
"$G" devices || exit 1
dev=${DEVICE:-$("$G" devices | awk 'NR > 1 && $0 ~ / (discrete|integrated|virtual)[ -]/ {print $1; exit}')}
if [ -z "$dev" ]; then
    echo "device: no GPU among the Vulkan devices (DEVICE=N picks one anyway)"
    exit 77
fi
cpu=$("$G" devices | awk 'NR > 1 && / cpu / {print $1; exit}')
echo "device: using device $dev"

fails=0
stage "correctness on device $dev"
for s in cornell teapot; do
    f=scenes/$s.gltf
    [ -f "$f" ] || { "$G" scene "$s" -o "$out/$s.gltf" >/dev/null && f=$out/$s.gltf; }
    "$G" render "$f" --device "$dev" --validate --size 128x128 --spp 256 -o "$out/$s-gpu.exr" --quiet || {
        echo "FAIL: $s renders on device $dev"; fails=$((fails + 1)); continue; }
    if [ -n "$cpu" ] && [ "$cpu" != "$dev" ]; then
        "$G" render "$f" --device "$cpu" --size 128x128 --spp 256 --seed 7 -o "$out/$s-cpu.exr" --quiet &&
            "$G" diff "$out/$s-gpu.exr" "$out/$s-cpu.exr" --max-rel-bias 0.02 || {
            echo "FAIL: $s on device $dev against lavapipe"; fails=$((fails + 1)); }
    fi
done
for f in "$A/gltf/TransmissionTest/glTF/TransmissionTest.gltf" "$A/gltf/DamagedHelmet/glTF/DamagedHelmet.gltf"; do
    [ -f "$f" ] || { echo "skipped: $f is absent"; continue; }
    "$G" render "$f" --device "$dev" --validate --size 128x128 --spp 16 -o "$out/m.exr" --quiet ||
        { echo "FAIL: $f renders on device $dev"; fails=$((fails + 1)); }
done
anim=$A/gltf/CesiumMan/glTF/CesiumMan.gltf
[ -f "$anim" ] && { "$G" render "$anim" --device "$dev" --validate --at 1.5 --size 128x128 --spp 16 -o "$out/a.exr" --quiet ||
    { echo "FAIL: an animated frame on device $dev"; fails=$((fails + 1)); }; }

stage "benchmarks on device $dev"
"$G" bench scenes/cornell.gltf --device "$dev" --seconds 2
"$G" bench --generate 250000 --device "$dev" --seconds 2
helmet=$A/gltf/DamagedHelmet/glTF/DamagedHelmet.gltf
[ -f "$helmet" ] && "$G" bench "$helmet" --device "$dev" --seconds 2
"$G" bench scenes/cornell.gltf --paths --device "$dev" --seconds 2
[ -f "$helmet" ] && "$G" bench "$helmet" --paths --env 1 --device "$dev" --seconds 2
stage "done: $fails failure(s)"
[ "$fails" = 0 ]
