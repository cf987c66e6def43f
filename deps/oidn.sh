#!/usr/bin/env bash
# oidn.sh DIR: Intel Open Image Denoise 2's CPU libraries for `render --denoise` and `gonio
# denoise` (src/core/denoise.h, docs/denoise.md) in DIR/lib, where gonio loads them at run
# time. Debian 12 packages no OIDN 2: they come from the pyoidn wheel, which the machine's pip
# downloads from its configured index (pip itself: deps/debian.sh oidn); the RT filter's
# weights (in _core), the CPU device and TBB are unpacked from it, not the GPU devices'
# libraries (CUDA, HIP, SYCL), which the CPU device does not load. Version pinned: the one
# measured in docs/performance.md.
#
# Once the libraries are there nothing is fetched again; remove DIR to fetch them anew. When
# pip cannot fetch the wheel, or it lacks a library, DIR is removed and the script fails,
# saying which.
set -u
OIDN_VERSION=2.5.1
WHEEL=pyoidn==$OIDN_VERSION.0
FILES="libOpenImageDenoise.so.2 libOpenImageDenoise_core.so.$OIDN_VERSION
    libOpenImageDenoise_device_cpu.so.$OIDN_VERSION libtbb.so.12"
dir=${1:?usage: oidn.sh DIR}

there=1
for f in $FILES; do [ -f "$dir/lib/$f" ] || there=0; done
if [ $there = 1 ]; then
    echo "gonio: Open Image Denoise $OIDN_VERSION is in $dir/lib (remove $dir to fetch it again)"
    exit 0
fi
rm -rf "$dir/wheel" "$dir/lib" && mkdir -p "$dir/wheel" "$dir/lib" || exit 1
echo "gonio: fetching Open Image Denoise $OIDN_VERSION (pip: $WHEEL) into $dir"
python3 -m pip download -q --retries 1 --timeout 30 --no-deps --only-binary=:all: --platform manylinux2014_x86_64 \
    -d "$dir/wheel" "$WHEEL" ||
    { rm -rf "$dir"; echo "gonio: pip could not fetch $WHEEL"; exit 1; }
# shellcheck disable=SC2086 # (FILES: one name a word)
python3 - "$dir" $FILES <<'PY' || { rm -rf "$dir"; echo "gonio: the pyoidn wheel lacks the expected libraries"; exit 1; }
import glob, os, sys, zipfile
d = sys.argv[1]
z = zipfile.ZipFile(glob.glob(os.path.join(d, "wheel", "*.whl"))[0])
for f in sys.argv[2:]:
    open(os.path.join(d, "lib", f), "wb").write(z.read("pyoidn/oidn/lib/" + f))
PY
rm -rf "$dir/wheel"
echo "gonio: $dir/lib/libOpenImageDenoise.so.2 and its CPU device are in place"
