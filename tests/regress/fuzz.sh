#!/usr/bin/env bash
# fuzz.sh: the inputs in tests/fuzz/regress that once crashed a fuzz target (make fuzz,
# tests/fuzz/run.sh), replayed through the program: each is refused with exit 1 and an
# error naming it, never a signal or a sanitizer report. EXRs go through gonio diff,
# anything else through gonio info (scene_load).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
shopt -s nullglob
files=("$(dirname "$0")"/../fuzz/regress/*)
[ ${#files[@]} -gt 0 ] || skip_all "no inputs in tests/fuzz/regress"
for f in "${files[@]}"; do
    case $f in
        *.exr) check_fails "$(basename "$f"): refused" 1 "$G" diff "$f" "$f" ;;
        *) check_fails "$(basename "$f"): refused" 1 "$G" info "$f" ;;
    esac
    check "... with an error naming it" grep -q "$(basename "$f")" "$tmp/last"
done
finish
