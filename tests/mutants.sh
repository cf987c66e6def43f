#!/usr/bin/env bash
# mutants.sh (make mutants): the fast tier has teeth. Each mutant below is a deliberate bug
# written into a scratch copy of the tree (the working tree as it is, build folder
# included, so only what the bug touches is rebuilt); the copy is built and the fast tier
# (tests/run.sh --stop) must fail. The jobs a mutant names run first, alone: jobs of the fast
# tier, so their failing is the fast tier's; where they all pass, the whole fast tier runs.
# Prints, per mutant, the job that killed it or SURVIVED;
# exit 1 when a mutant survives or no longer applies (the code it edits has changed: update
# its text here).
#   tests/mutants.sh [NAME...]    (the mutants whose names contain NAME; all by default)
# Environment: config (build config, default release), TEST_JOBS (jobs at once).
set -u
cd "$(dirname "$0")/.."
root=$PWD
config=${config:-release}

# name|jobs to try first|file|the exact text|its replacement: each text must occur exactly
# once in its file.
mutants=(
    # BSDF: GGX's distribution without its alpha^2 numerator (not normalised for alpha != 1).
    "brdf-ggx-norm|unit/brdf|glsl/lib/brdf_scatter.glsl|    return a * a / (BRDF_PI * d * d);|    return a / (BRDF_PI * d * d);"
    # BSDF sampling: Blinn's pdf with the Jacobian of the half vector at the normal's cosine
    # instead of wo.h: f is right, the sampled directions' density is not what pdf says.
    "brdf-blinn-pdf|unit/brdf|glsl/lib/brdf_bsdf.glsl|        pdf = (n + 1.0) / (2.0 * BRDF_PI) * v / (4.0 * oh);|        pdf = (n + 1.0) / (2.0 * BRDF_PI) * v / (4.0 * h.z);"
    # merge: every file weighted by the first one's sample count, not its own.
    "merge-weights|unit/path regress/path.sh|src/cli/cmd_merge.c|                    double w = (double)in->spp[i], xv;|                    double w = (double)in->spp[0], xv;"
    # loader: the check that an accessor fits in its buffer view, removed.
    "loader-accessor-bounds|unit/scene regress/invalid.sh|src/scene/gltf_check.cpp|        if (!fits(a.byteOffset, stride, a.count, es, v.byteLength))|        if (false)"
    # path tracer: light sampling's area-to-solid-angle Jacobian without the emitter's cosine.
    "path-light-pdf|unit/path|glsl/kernels/path.comp|            s.pdf = e.pdf / e.area * d2 / c;|            s.pdf = e.pdf / e.area * d2;"
)

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
echo "mutants: copying the tree and build/$config to $scratch"
# The working tree as it is (tracked and untracked files git does not ignore) and the
# build folder, times kept, so that make rebuilds only what a mutant changes.
git ls-files -z -c -o --exclude-standard | tar -c --null -T - -f - | tar -x -C "$scratch" -f -
mkdir -p "$scratch/build"
[ -d "build/$config" ] && cp -a "build/$config" "$scratch/build/"

survived=0
killed=0
for m in "${mutants[@]}"; do
    IFS='|' read -r name first file from to <<<"$m"
    if [ $# -gt 0 ]; then
        hit=0
        for o in "$@"; do case $name in *"$o"*) hit=1 ;; esac; done
        [ $hit = 1 ] || continue
    fi
    echo "== mutant $name ($file)"
    if ! python3 - "$scratch/$file" "$from" "$to" <<'PY'; then
import sys
path, a, b = sys.argv[1:]
s = open(path).read()
if s.count(a) != 1:
    sys.exit("  the text occurs %d times in %s (expected once): update tests/mutants.sh" % (s.count(a), path))
open(path, "w").write(s.replace(a, b))
PY
        survived=$((survived + 1))
        continue
    fi
    t0=$SECONDS
    if ! make -C "$scratch" -j2 config=$config all "build/$config/unit_tests" "build/$config/testtool" \
        >"$scratch/build.log" 2>&1; then
        echo "  the mutant does not build (a mutant must compile):"
        tail -n 20 "$scratch/build.log" | sed 's/^/    /'
        survived=$((survived + 1))
    else
        fast_tier() { (cd "$scratch" && GONIO=build/$config/gonio UNIT=build/$config/unit_tests \
            TESTTOOL=build/$config/testtool CONFIG=$config tests/run.sh --stop "$@") >"$scratch/test.log" 2>&1; }
        # shellcheck disable=SC2086 # (the job names split at spaces)
        fast_tier $first
        rc=$?
        [ $rc = 0 ] && { fast_tier; rc=$?; }
        if [ $rc = 0 ]; then
            echo "  SURVIVED: the fast tier passes with this bug ($((SECONDS - t0)) s)"
            survived=$((survived + 1))
        else
            by=$(sed -n 's/^FAILED: //p' "$scratch/test.log" | tr '\n' ' ')
            echo "  killed by: ${by:-exit $rc} ($((SECONDS - t0)) s)"
            grep -E '^ +FAIL|CHECK failed' "$scratch/test.log" | head -n 3 | sed 's/^/    /'
            killed=$((killed + 1))
        fi
    fi
    # Undo: the original text back, with a new time, so that the next build redoes it.
    cp "$root/$file" "$scratch/$file"
    touch "$scratch/$file"
done
echo "mutants: $killed killed, $survived survived"
[ "$survived" = 0 ]
