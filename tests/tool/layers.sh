#!/usr/bin/env bash
# layers.sh LAYER:BELOW... : checks the include graph against the layers (the Makefile's
# LAYERS, passed as "render:core scene accel" and so on; docs/architecture.md). Every
# #include "X" of src/LAYER must find X in src/LAYER, in a layer below it, or in glsl/lib (the
# render and cli layers also a kernel's generated SPIR-V header); an include that names a
# path is refused too, since it would go around the per-layer include paths that the build
# compiles each layer with. Inside src/render, each part includes only the parts below it
# (render_parts, below). glsl/lib includes only glsl/lib, glsl/kernels glsl/lib. Prints
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
# Inside src/render the files are parts that own their state (docs/architecture.md): a part
# is NAME.c with its header NAME.h, and may include the headers of the parts listed after
# it here, never the renderer's (render.h) unless listed, so that no part calls back up.
# A file of src/render that is no part here is a violation too.
render_parts=(
    "brdf:"
    "render_geometry:"
    "render_modes:"
    "render_accum:"
    "render_limits:render_geometry"
    "render_lights:render_geometry"
    "render_gouraud:render_geometry"
    "render_kernels:render_modes"
    "render_material:brdf"
    "brdf_runner:brdf render_material"
    "render:render_accum render_geometry render_gouraud render_kernels render_lights render_modes render_limits render_material brdf"
    "render_output:render"
    "render_default_light:render"
)
declare -A part_may
for spec in "${render_parts[@]}"; do part_may[${spec%%:*}]=" ${spec%%:*} ${spec#*:} "; done
for f in src/render/*.c src/render/*.h; do
    [ -e "$f" ] || continue
    part=$(basename "${f%.*}")
    if [ -z "${part_may[$part]:-}" ]; then
        violation "$f: not a part of src/render (tests/tool/layers.sh: render_parts)"
        continue
    fi
    while IFS= read -r h; do
        [ -e "src/render/$h" ] || continue
        case ${part_may[$part]} in *" ${h%.h} "*) continue ;; esac
        violation "$f includes src/render/$h: the part $part may include only the parts$(echo "${part_may[$part]}" | sed "s/ $part / /")"
    done < <(includes "$f")
done

for f in glsl/lib/* glsl/kernels/*.comp; do
    while IFS= read -r h; do
        [ -e "glsl/lib/$h" ] || violation "$f includes \"$h\": the kernels include only glsl/lib"
    done < <(includes "$f")
done
[ $bad = 0 ] && echo "layers: ${layers[*]}: no include goes up or sideways; the parts of src/render include only those below them"
exit $bad
