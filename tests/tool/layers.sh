#!/usr/bin/env bash
# layers.sh LAYER:BELOW... : checks the include graph against the layers (the Makefile's
# LAYERS, passed as "render:core scene accel" and so on; docs/architecture.md). Every
# #include "X" of src/LAYER must find X in src/LAYER, in a layer below it, or in glsl/lib (the
# render and cli layers also a kernel's generated SPIR-V header); an include that names a
# path is refused too, since it would go around the per-layer include paths that the build
# compiles each layer with. glsl/lib includes only glsl/lib, glsl/kernels glsl/lib. Prints
# each violation; exit 1 when there is one.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root" || exit 1
declare -A below
layers=()
for spec in "$@"; do
    layers+=("${spec%%:*}")
    below[${spec%%:*}]=${spec#*:}
done
[ ${#layers[@]} -gt 0 ] || { echo "usage: layers.sh LAYER:BELOW..." >&2; exit 2; }
bad=0
violation() { echo "layers: $*"; bad=1; }

# includes FILE: the names in its #include "..." lines.
includes() { sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$1"; }

for layer in "${layers[@]}"; do
    [ -d "src/$layer" ] || { violation "src/$layer: no such folder"; continue; }
    for f in src/"$layer"/*.c src/"$layer"/*.cpp src/"$layer"/*.h; do
        [ -e "$f" ] || continue
        while IFS= read -r h; do
            if [[ $h == */* ]]; then
                violation "$f includes \"$h\": a path goes around the layers' include paths"
                continue
            fi
            [ -e "src/$layer/$h" ] || [ -e "glsl/lib/$h" ] && continue
            ok=
            for l in ${below[$layer]}; do [ -e "src/$l/$h" ] && ok=1; done
            [ -n "$ok" ] && continue
            if { [ "$layer" = render ] || [ "$layer" = cli ]; } && [ -e "glsl/kernels/${h%.h}.comp" ]; then
                continue
            fi
            owner=$(for l in "${layers[@]}"; do [ -e "src/$l/$h" ] && echo "src/$l"; done | head -n 1)
            if [ -n "$owner" ]; then
                violation "$f includes $owner/$h: $layer may include only ${below[$layer]:-its own headers}${below[$layer]:+ and its own}"
            else
                violation "$f includes \"$h\", which no layer has"
            fi
        done < <(includes "$f")
    done
done
for f in glsl/lib/* glsl/kernels/*.comp; do
    while IFS= read -r h; do
        [ -e "glsl/lib/$h" ] || violation "$f includes \"$h\": the kernels include only glsl/lib"
    done < <(includes "$f")
done
[ $bad = 0 ] && echo "layers: ${layers[*]}: no include goes up or sideways"
exit $bad
