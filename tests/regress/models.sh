#!/usr/bin/env bash
# models.sh: what is made from the table of BRDF models (glsl/lib/brdf_models.h) outside the
# code: docs/brdf.md prints `gonio brdf --list` as it is and has a section for every model,
# a `###` heading that names it in backquotes. (path.sh renders every model of the list.)
. "$(dirname "$0")/../lib.sh"
G=$GONIO
D=docs/brdf.md

check "brdf --list" "$G" brdf --list
cp "$tmp/out" "$tmp/list"
check "the table has models" test -s "$tmp/list"
# the fenced block after the sentence that announces --list
awk '/gonio brdf --list` *$/ || /`gonio brdf --list`/ { want = 1 } want && /^```$/ { if (inside) exit; inside = 1; next }
     inside { print }' "$D" >"$tmp/doc-list"
check "docs/brdf.md's --list block is the program's" diff "$tmp/doc-list" "$tmp/list"
while read -r model _; do
    check "docs/brdf.md has a section on $model" grep -q "^### .*\`$model\`" "$D"
done <"$tmp/list"
finish
