#!/usr/bin/env bash
# source.sh: the walls the source tree keeps, each shown to stand and to fail loudly:
# - a BRDF model with more parameters than BRDF_MAX_PARAMS (src/render/brdf.h) fails every
#   build configuration (release, debug, sanitize, fuzz) with a message naming the limit:
#   a copy of glsl/lib whose material table gives the glTF model a 19th parameter, compiled
#   with each configuration's own command (make -n);
# - the include order of the layers and of src/render's parts (tests/tool/layers.sh) refuses
#   a part that includes the renderer, in a copy of the tree;
# - what the reference pages claim of the source (tests/tool/doc_claims.py: paths, names,
#   the recipes' diffs, the feature bits in use) is true, and a false claim is caught.
. "$(dirname "$0")/../lib.sh"
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root" || exit 1

# ---- BRDF_MAX_PARAMS ------------------------------------------------------------------------
# compile_cmd CONFIG [MAKE ARGS]: the configuration's command that compiles src/render/brdf.c,
# as a syntax check (no object, no dependency file)
compile_cmd() {
    local config=$1; shift
    make -n -B --no-print-directory config="$config" "$@" "build/$config/src/render/brdf.o" 2>/dev/null |
        grep -- "-o build/$config/src/render/brdf.o" | head -n 1 |
        sed "s| -o build/$config/src/render/brdf.o| -fsyntax-only|; s| -MMD||; s| -MP||"
}
mkdir -p "$tmp/wide"
cp -r glsl/lib "$tmp/wide/"
# alphaCutoff, a factor without a --brdf parameter today, given one: the glTF model's 19th
sed -i 's|"alphaCutoff", 0.5f, 0, GN_INF, CLAMP, GN_FEAT_NONE, NO_BRDF)|"alphaCutoff", 0.5f, 0, GN_INF, CLAMP, GN_FEAT_NONE, BRDF("alpha-cutoff", 0.5f, 0, 1))|' \
    "$tmp/wide/lib/material.h"
check "the copy of the material table has a 19th glTF parameter" grep -q '"alpha-cutoff"' "$tmp/wide/lib/material.h"
release=$(compile_cmd release)
check "the release build's command for brdf.c" test -n "$release"
check "brdf.c compiles as it is" sh -c "$release"
for config in release debug sanitize fuzz; do
    cmd=$(compile_cmd $config)
    if [ $config = fuzz ]; then
        # make fuzz's compiler is clang, which CI installs after the fast tier; without it, gcc
        # with the configuration's flags (no -Werror: the case the wall is for) but libFuzzer's
        if command -v clang >/dev/null; then
            cmd=$(compile_cmd fuzz CC=clang CXX=clang++)
        else
            cmd=$(compile_cmd fuzz CC=gcc CXX=g++ | sed 's/,fuzzer-no-link//')
        fi
        check "config=fuzz compiles without -Werror" sh -c "echo '$cmd' | grep -qv -- -Werror"
    fi
    check_fails "config=$config: a 19th BRDF parameter fails the build" 1 sh -c \
        "${cmd//-Iglsl\/lib/-I$tmp/wide/lib} || exit 1"
    check "config=$config: the error names BRDF_MAX_PARAMS" grep -q "more parameters than BRDF_MAX_PARAMS" "$tmp/last"
done

# ---- the layers and the parts of src/render ----------------------------------------------------
layer_args=$(make -n --no-print-directory check-layers | sed -n 's|^tests/tool/layers.sh ||p')
check "make check-layers' arguments" test -n "$layer_args"
mkdir -p "$tmp/tree/tests/tool"
cp -r src glsl "$tmp/tree/"
cp tests/tool/layers.sh "$tmp/tree/tests/tool/"
copy_layers() { eval "\"$tmp/tree/tests/tool/layers.sh\" $layer_args"; } # (the arguments as make quotes them)
check "the tree's includes keep the layers" copy_layers
sed -i '0,/#include "render_lights.h"/s//#include "render_lights.h"\n#include "render.h"/' "$tmp/tree/src/render/render_lights.c"
check_fails "a part that includes the renderer is refused" 1 copy_layers
check "the refusal names the part and the header" grep -q "render_lights.c includes src/render/render.h" "$tmp/last"

# ---- what the docs claim ---------------------------------------------------------------------
docs=(docs/*.md README.md tests/README.md)
check "the docs' claims of the source hold" python3 tests/tool/doc_claims.py "${docs[@]}"
sed 's/There are 64 bits, \([0-9]*\)/There are 64 bits, 1\1/' docs/architecture.md >"$tmp/architecture.md"
check_fails "a wrong count of feature bits is caught" 1 python3 tests/tool/doc_claims.py "$tmp/architecture.md"
sed 's/^-    X(COST, 7u/-    X(COST, 70u/' docs/architecture.md >"$tmp/architecture.md"
check_fails "a recipe's diff that does not apply is caught" 1 python3 tests/tool/doc_claims.py "$tmp/architecture.md"
finish
