#!/usr/bin/env bash
# cli.sh: what every command shares: --opt=value is --opt value, unknown options are
# reported as such (exit 2) without taking the next argument.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
C=$PWD/scenes/cornell.gltf

# ---- --opt=value --------------------------------------------------------------------------
# The same command in both forms gives the same bits.
check "render --opt value" "$G" render $C -o "$tmp/sp.exr" --mode phong --spp 2 --size 24x16 --seed 3 --quiet
check "render --opt=value" "$G" render $C --output="$tmp/eq.exr" --mode=phong --spp=2 --size=24x16 --seed=3 --quiet
check "render: both forms, identical pixels" "$G" diff "$tmp/sp.exr" "$tmp/eq.exr" --max-error=0 --quiet
check_fails "diff --max-error=0 on other pixels fails" 1 "$G" diff "$tmp/sp.exr" "$C" --max-error=0 --quiet
check "teapot --level=2 --output=" "$G" teapot --level=2 --output="$tmp/t-eq.gltf"
check "teapot --level 2 -o" "$G" teapot --level 2 -o "$tmp/t-sp.gltf"
check "teapot: both forms, the same file" cmp "$tmp/t-eq.gltf" "$tmp/t-sp.gltf"
check "scene cornell --output=" "$G" scene cornell --output="$tmp/c.gltf"
check "merge --output=" "$G" merge "$tmp/sp.exr" "$tmp/eq.exr" --output="$tmp/m.exr"
check "merged: 4 spp" sh -c "exrheader '$tmp/m.exr' | grep -q 'gonio:spp (type int): 4'"
check "bench --generate=N --size= --seconds=" "$G" bench --generate=2000 --size=16x16 --seconds=0.05
check "brdf MODEL --PARAM=V --theta=" "$G" brdf phong --exponent=8 --theta=45 --output="$tmp/lobe.png" --size=240x240
check "compare --modes= --spp= --size= --output=" "$G" compare $C --modes=flat,phong --spp=1 --size=16x16 \
    --output="$tmp/cmp" --quiet
check "compare wrote flat.exr" test -s "$tmp/cmp/flat.exr"
# Each option's own parser sees the value: its own message, naming the value.
for c in "render $C -o $tmp/x.exr --spp" "preview $C --frames" "bench --seconds" "brdf phong --theta" \
    "compare $C -o $tmp/cmp --spp" "teapot -o $tmp/x.gltf --level" "diff $tmp/sp.exr $tmp/eq.exr --max-rmse"; do
    check_fails "${c%% *} ${c##* }=bogus: a usage error" 2 "$G" $c=bogus
    check "${c%% *} ${c##* }=bogus: the option's own message" \
        sh -c "grep -q bogus '$tmp/last' && ! grep -q 'unknown option' '$tmp/last'"
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
check "no output after usage errors" test ! -e "$tmp/x.exr"
finish
