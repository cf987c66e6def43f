#!/usr/bin/env bash
# debian.sh GROUP: the Debian 12 packages of one group, checked by what the group uses (the
# commands, headers and files, not dpkg's records: a machine that has them some other way
# passes) and, where something is missing, installed: as root by apt-get (an update first
# only when the install fails without one), otherwise the exact apt-get line to run as root
# is printed and the script fails. Nothing is printed when nothing is missing: make runs it
# before every build.
#   build  what make compiles with: compilers, the shader tools, the libraries (and the
#          pkg-config modules of $PKGS, the Makefile's list, which make passes), lavapipe
#   test   what make test's scripts run besides the program: validation layers, ImageMagick,
#          X for the preview's tests, ...
#   fuzz   clang and its libFuzzer runtime (make fuzz)
#   farm   Slurm and munge (make test-farm)
#   peer   python3-venv (make bench-peer: deps/mitsuba.sh makes a venv)
#   oidn   pip (make denoiser: deps/oidn.sh fetches a wheel)
set -u
group=${1:?usage: debian.sh build|test|fuzz|farm|peer|oidn}
# By hand, without make: the pkg-config modules as the Makefile lists them.
PKGS=${PKGS:-$(sed -n 's/^PKGS := //p' "$(dirname "$0")/../Makefile")}

# have_GROUP: the group's packages are there (quiet).
have_build() {
    command -v glslangValidator && command -v spirv-val && command -v pkg-config && command -v help2man &&
        pkg-config --exists $PKGS && ls /usr/include/meshoptimizer.h && ls /usr/share/vulkan/icd.d/lvp_icd*.json
}
have_test() {
    ls /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json && command -v exrheader &&
        command -v xvfb-run && command -v xauth && command -v import && command -v xwd && command -v xdotool &&
        command -v man && command -v cwebp && test -x /usr/bin/python3 && convert -list format | grep -q 'EXR.*rw'
}
have_fuzz() {
    command -v clang && command -v clang++ &&
        echo 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n) { return 0; }' |
        clang -x c -fsanitize=fuzzer -o /dev/null -
}
have_farm() { command -v slurmctld && command -v slurmd && command -v munged; }
have_peer() { python3 -c 'import ensurepip, venv'; }
have_oidn() { python3 -m pip --version; }

case $group in
build)
    # nlohmann-json3-dev: the JSON library tinygltf parses with, which gltf_json.cpp uses to
    # check the document itself (tinygltf's package does not depend on it).
    packages="gcc g++ make pkg-config libvulkan-dev glslang-tools spirv-tools libglfw3-dev
        libopenexr-dev libtinygltf-dev nlohmann-json3-dev libpng-dev zlib1g-dev libstb-dev mesa-vulkan-drivers help2man
        libdraco-dev libmeshoptimizer-dev libwebp-dev libzstd-dev" ;;
test)
    # man-db: tests/regress/cli.sh renders the installed man page with man -l.
    # webp: cwebp, the tests' encoder of WebP textures (tests/regress/image_formats.sh).
    # python3: the scripts' small helpers (tests/tool/*.py; the standard library only).
    # libmagickcore-6.q16-6-extra: ImageMagick's EXR coder (only a recommendation of
    # imagemagick, which --no-install-recommends leaves out); tests/regress/diff.sh writes
    # EXRs with it.
    packages="vulkan-validationlayers openexr xvfb xauth imagemagick libmagickcore-6.q16-6-extra
        x11-apps xdotool man-db webp python3" ;;
fuzz) packages="clang libclang-rt-14-dev" ;; # Debian 12's clang is clang-14
farm) packages="slurm-wlm munge" ;;
peer) packages="python3-venv" ;;
oidn) packages="python3-pip" ;;
*)
    echo "debian.sh: no group '$group' (build, test, fuzz, farm, peer, oidn)" >&2
    exit 2 ;;
esac
packages=$(echo $packages) # one line, single spaces

have_$group >/dev/null 2>&1 && exit 0
if [ "$(id -u)" != 0 ]; then
    echo "gonio: missing packages; run as root:"
    echo "  apt-get install $packages"
    exit 1
fi
echo "gonio: installing Debian packages: $packages"
export DEBIAN_FRONTEND=noninteractive
{ apt-get install -y -q --no-install-recommends $packages ||
    { apt-get update -q && apt-get install -y -q --no-install-recommends $packages; }; } >/dev/null ||
    { echo "gonio: apt-get install failed"; exit 1; }
