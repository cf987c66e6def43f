#!/usr/bin/env bash
# invalid.sh: `gonio render` over every glTF-Validator test case in ../shared/assets.
# A file whose validator report has errors must either fail (exit 1) with a message that
# names the file and write no output, or render with a warning. The valid controls must
# render, or fail only because they draw no triangle. Nothing may crash or hang.
. "$(dirname "$0")/../lib.sh"
G=$GONIO
dir=${GONIO_ASSETS:-../shared/assets}/invalid-gltf
[ -d "$dir" ] || skip_all "$dir is absent"

n=0
while IFS= read -r f; do
    report="$f.report.json"
    [ -f "$report" ] || continue
    n=$((n + 1))
    errors=$(grep -o '"numErrors": *[0-9]*' "$report" | head -n 1 | grep -o '[0-9]*$')
    out="$tmp/out-$n.exr"
    timeout 60 "$G" render "$f" -o "$out" --spp 1 --size 8x8 --quiet >"$tmp/log" 2>&1
    rc=$?
    base=$(basename "$f")
    if [ $rc -ge 124 ]; then
        fail "$f: crashed or hung (exit $rc)"; sed 's/^/    /' "$tmp/log" | tail -n 5
    elif [ "${errors:-0}" -gt 0 ]; then
        if [ $rc = 1 ] && grep -qF "$base" "$tmp/log" && [ ! -e "$out" ]; then pass
        elif [ $rc = 0 ] && grep -q "warning" "$tmp/log" && [ -s "$out" ]; then pass
        else fail "$f ($errors validator errors): exit $rc"; sed 's/^/    /' "$tmp/log" | tail -n 5; fi
    else
        if [ $rc = 0 ] || { [ $rc = 1 ] && grep -q "no triangles" "$tmp/log"; }; then pass
        else
            case "$base" in
            # An http:// buffer is valid glTF, but gonio reads no network resources.
            non_relative_uri.gltf) pass ;;
            # tinygltf refuses unknown accessor types, which the validator only warns about.
            unknown_type.gltf) pass ;;
            *) fail "$f (valid): exit $rc"; sed 's/^/    /' "$tmp/log" | tail -n 5 ;;
            esac
        fi
    fi
    rm -f "$out"
done < <(find "$dir" -type f \( -name '*.gltf' -o -name '*.glb' \) | sort)
[ $n -gt 50 ] || fail "only $n validator cases found"
finish
