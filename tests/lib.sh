# lib.sh: helpers for the regression scripts (sourced). Each script counts checks with
# pass/fail, and ends with `finish`, which prints "NAME: N passed, N failed" and exits.
set -u
name=$(basename "$0" .sh)
n_pass=0
n_fail=0
tmp=${TEST_TMP:-$(mktemp -d)}/$name
mkdir -p "$tmp"
pass() { n_pass=$((n_pass + 1)); }
fail() { n_fail=$((n_fail + 1)); echo "  FAIL: $*"; }
check() { # check DESCRIPTION COMMAND...: passes when the command succeeds
    local what=$1; shift
    if "$@" >"$tmp/out" 2>&1; then pass; else fail "$what"; sed 's/^/    /' "$tmp/out" | tail -n 20; fi
}
check_fails() { # check_fails DESCRIPTION EXPECTED_STATUS COMMAND...
    local what=$1 want=$2; shift 2
    "$@" >"$tmp/out" 2>&1
    local got=$?
    cp "$tmp/out" "$tmp/last" # what the command printed, for checks that follow
    if [ "$got" = "$want" ]; then pass; else fail "$what (exit $got, expected $want)"; sed 's/^/    /' "$tmp/out" | tail -n 20; fi
}
skip_all() { echo "  skipped: $*"; exit 77; }
finish() {
    echo "$name: $n_pass passed, $n_fail failed"
    [ "$n_fail" = 0 ]
}
