#!/usr/bin/env bash
# run.sh: the whole test suite (make test): the C unit tests, then every shell regression
# script in tests/regress, all on lavapipe with the Vulkan validation layer on.
# Environment: GONIO (the program), UNIT (the unit-test binary), CONFIG (build config).
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
cd "$root"
export GONIO=${GONIO:-build/release/gonio} UNIT=${UNIT:-build/release/unit_tests}
export TESTTOOL=${TESTTOOL:-build/release/testtool}
export GONIO=$(realpath "$GONIO") UNIT=$(realpath "$UNIT") TESTTOOL=$(realpath "$TESTTOOL")
# Every Vulkan instance the tests create validates; any message fails that run.
export GONIO_VALIDATE=1
# Tests run on lavapipe, the device every developer machine and CI has.
export VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)}
export GONIO_ASSETS=${GONIO_ASSETS:-$root/../shared/assets}
# Mesa and LLVM keep some allocations until exit; the suppressions name only those.
export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0"
# A small quarantine: lavapipe allocates and frees a lot, and the default 256 MB makes
# every run page-fault its way through it (4x slower).
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:quarantine_size_mb=16"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
export TEST_TMP=$(mktemp -d)
trap 'rm -rf "$TEST_TMP"' EXIT

if [ ! -d "$GONIO_ASSETS" ]; then
    echo "note: $GONIO_ASSETS is absent: the tests that need third-party assets will skip"
fi

failed=0
passed=0
skipped=0
echo "== unit tests ($CONFIG)"
if "$UNIT"; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAILED: unit tests"; fi
for t in tests/regress/*.sh; do
    echo "== $t"
    "$t"
    case $? in
        0) passed=$((passed + 1)) ;;
        77) skipped=$((skipped + 1)) ;;
        *) failed=$((failed + 1)); echo "FAILED: $t" ;;
    esac
done
echo "suites: $passed passed, $failed failed, $skipped skipped"
[ "$failed" = 0 ]
