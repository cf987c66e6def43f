#!/usr/bin/env bash
# make-images.sh: regenerates every figure in docs/img (make docs-images): the BRDF lobe
# plots and material balls of docs/brdf.md section 6, the shading comparison and sweep of
# docs/shading.md, the path-traced scenes of docs/path-tracing.md and its pictures of the glTF
# extensions' test scenes (tests/regress writes them; the glTF sample
# models are skipped when $GONIO_ASSETS is absent). Environment: GONIO (the program;
# default build/gonio), TESTTOOL (default: testtool beside it), GONIO_ASSETS (default
# ../shared/assets).
set -eu
cd "$(dirname "$0")/.."
G=${GONIO:-build/gonio}
img=docs/img
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p $img
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf # fonts-dejavu-core; ImageMagick's default may be absent
label_font=$( [ -f $font ] && echo "-font $font" )

# ---- docs/brdf.md -------------------------------------------------------------------------
"$G" brdf lambert --theta 30 -o $img/brdf-lambert.png
"$G" brdf mirror --theta 40 -o $img/brdf-mirror.png
"$G" brdf phong --diffuse 0.5 --specular 0.5 --exponent 20 --theta 30 -o $img/brdf-phong.png
"$G" brdf blinn-phong --diffuse 0.5 --specular 0.5 --exponent 50 --theta 30 -o $img/brdf-blinn-phong.png
"$G" brdf torrance-sparrow --diffuse 0.5 --specular 0.5 --exponent 50 --theta 45 -o $img/brdf-torrance-sparrow.png
"$G" brdf beckmann --alpha 0.2 --theta 45 -o $img/brdf-beckmann.png
"$G" brdf ggx --alpha 0.2 --theta 45 -o $img/brdf-ggx.png
"$G" brdf conductor --alpha 0.2 --theta 60 -o $img/brdf-conductor.png
"$G" brdf dielectric --theta 40 -o $img/brdf-glass.png
"$G" brdf dielectric --alpha 0.2 --theta 40 -o $img/brdf-dielectric.png
"$G" brdf gltf --roughness 0.4 --theta 45 -o $img/brdf-gltf.png
"$G" brdf gltf --metallic 1 --roughness 0.3 --anisotropy 0.8 --theta 45 -o $img/brdf-gltf-aniso.png
"$G" brdf gltf --metallic 1 --roughness 0.3 --anisotropy 0.8 --anisotropy-rotation 1.5708 --theta 45 \
    -o $img/brdf-gltf-aniso-across.png
"$G" brdf gltf --roughness 0.3 --metallic 1 --base-color 0.5 --iridescence 1 --iridescence-thickness 400 --theta 45 \
    -o $img/brdf-gltf-iridescence.png
"$G" brdf gltf --roughness 0.5 --base-color 0.8 --diffuse-transmission 0.6 --diffuse-transmission-color 0.9,0.6,0.2 \
    --theta 45 -o $img/brdf-gltf-diffuse-transmission.png
ball() { # ball NAME MODEL [PARAMS...]
    local name=$1; shift
    "$G" brdf "$@" --sphere --size 128x128 --spp 256 -o "$tmp/ball.exr" --png $img/brdf-ball-$name.png
}
ball lambert lambert
ball phong phong --diffuse 0.4,0.1,0.1 --specular 0.5 --exponent 64
ball ggx ggx --diffuse 0.1,0.2,0.5 --specular 0.5 --alpha 0.1
ball conductor conductor --alpha 0.2
ball dielectric dielectric --tint 0.5,0.8,1 --alpha 0.05
ball gltf gltf --base-color 0.8,0.3,0.1 --roughness 0.4 --metallic 0.5
ball aniso gltf --base-color 0.9 --metallic 1 --roughness 0.3 --anisotropy 0.8
ball aniso-across gltf --base-color 0.9 --metallic 1 --roughness 0.3 --anisotropy 0.8 --anisotropy-rotation 1.5708
ball iridescence gltf --base-color 0.5 --metallic 1 --roughness 0.25 --iridescence 1 --iridescence-thickness 400 \
    --iridescence-ior 1.33
ball diffuse-transmission gltf --base-color 0.3,0.6,0.2 --roughness 0.5 --diffuse-transmission 0.8 \
    --diffuse-transmission-color 0.9,0.8,0.3
ball clearcoat gltf --base-color 0.6,0.05,0.05 --metallic 0 --roughness 0.6 --clearcoat 1 --clearcoat-roughness 0.05
ball sheen gltf --base-color 0.1,0.1,0.35 --roughness 0.8 --sheen-color 0.9,0.7,0.9 --sheen-roughness 0.4

# ---- docs/shading.md ----------------------------------------------------------------------
# The OpenGL 1.x teapot in all four modes (path is skipped while unavailable), 320x240.
"$G" compare scenes/teapot.gltf -o "$tmp/teapot" --spp 256 --quiet
cp "$tmp/teapot/side-by-side.png" $img/shading-teapot.png
rm -f $img/shading-diff-*.png
for f in "$tmp"/teapot/diff-*.png; do cp "$f" $img/shading-$(basename "$f"); done
cp "$tmp/teapot/metrics.csv" $img/shading-teapot-metrics.csv
"$G" compare --sweep 1,2,4,8,16,32 teapot -o "$tmp/sweep" --quiet
cp "$tmp/sweep/sweep.png" $img/shading-sweep.png
cp "$tmp/sweep/sweep.csv" $img/shading-sweep.csv

# ---- README.md and docs/path-tracing.md ------------------------------------------------
"$G" render scenes/cornell.gltf -o "$tmp/cornell.exr" --png $img/cornell.png --size 320x320 --spp 256 --quiet
"$G" render scenes/cornell.gltf -o "$tmp/cornell-phong.exr" --png $img/cornell-phong.png --mode phong --size 320x320 --spp 16 --quiet

# glass, metals and a textured model under a sky: a lat-long map made here (blue zenith to a
# white horizon, a dark ground), rendered from the glTF sample models in place.
convert -size 512x128 gradient:'#5a8ee0'-'#f0f0ff' \( -size 512x128 gradient:'#505048'-'#100c08' \) \
    -append "$tmp/sky.exr"
assets=${GONIO_ASSETS:-../shared/assets}/gltf
if [ -d "$assets" ]; then
    sky() { # sky MODEL OUT.png [OPTIONS...]
        local model=$1 out=$2; shift 2
        "$G" render "$assets/$model/glTF/$model.gltf" --env "$tmp/sky.exr" -o "$tmp/sky-render.exr" \
            --png $img/$out "$@" --quiet
    }
    sky TransmissionTest path-glass.png --camera 0 --size 320x180 --spp 128
    sky MetalRoughSpheresNoTextures path-metals.png --size 256x256 --spp 64
    sky DamagedHelmet path-helmet.png --size 256x256 --spp 128
    # Every sample model as a new user renders it: no flags but the size (its own camera or
    # the framing view, its own lights or the studio environment).
    tiles=()
    for d in "$assets"/*/; do
        m=$(basename "$d")
        f=$(ls "$d"glTF/*.gltf 2>/dev/null | head -n 1)
        [ -n "$f" ] || continue
        "$G" render "$f" --png "$tmp/sample-$m.png" --size 160x160 --spp 64 --quiet
        tiles+=(-label "$m" "$tmp/sample-$m.png")
    done
    montage "${tiles[@]}" $label_font -tile 5x -geometry +2+2 -pointsize 11 \
        -background white "$tmp/samples.png"
    convert "$tmp/samples.png" -quality 85 $img/samples.jpg
fi

# ---- docs/path-tracing.md: the glTF extensions' test scenes ----------------------------
# The scenes that tests/regress/{textures,gltf_ext,volume}.sh write (the suites run here with
# TEST_TMP, which keeps them), rendered larger: what each check looks at.
t=$tmp/tests
mkdir -p "$t"
export GONIO=$(realpath "$G")
export TESTTOOL=$(realpath "${TESTTOOL:-$(dirname "$GONIO")/testtool}")
for s in textures gltf_ext volume; do
    TEST_TMP=$t tests/regress/$s.sh >"$t/$s.log" 2>&1 || { cat "$t/$s.log"; exit 1; }
done
tile() { # tile LABEL SCENE [RENDER OPTIONS...]: one labelled picture of a test scene
    local label=$1 scene=$2; shift 2
    "$G" render "$t/$scene" -o "$tmp/tile.exr" --png "$tmp/tile-${#tiles[@]}.png" --quiet "$@"
    tiles+=(-label "$label" "$tmp/tile-${#tiles[@]}.png")
}
sheet() { # sheet OUT.png COLUMNS: the tiles so far, then none
    montage "${tiles[@]}" $label_font -tile $2x -geometry +2+2 -pointsize 10 -background white $img/$1
    tiles=()
}
A="--mode albedo --spp 1 --size 120x120" N="--mode normal --spp 1 --size 120x120"
tiles=()
while read -r -u 3 scene label; do tile "$label" textures/$scene.gltf $A; done 3<<'EOF'
plain     no transform
offset    offset 0.25, -0.5
scale     scale 2, 0.5
rotation  rotation 30 deg
all       all three
uv1       TEXCOORD_1
uv1tt     transform texCoord 1
repeat    REPEAT
mirror    MIRRORED_REPEAT
clamp     CLAMP_TO_EDGE
mixed     CLAMP S, MIRROR T
linear    magFilter LINEAR
EOF
sheet gltf-textures.png 6
tile "float" textures/float_q.gltf $A
tile "quantized" textures/quant.gltf $A
tile "float normals" textures/nfloat.gltf $N
tile "byte normals" textures/nquant.gltf $N
sheet gltf-quantization.png 4
C="--spp 64 --size 160x120"
tile "teapot" gltf_ext/teapot.gltf $C
tile "Draco" gltf_ext/teapot-draco.gltf $C
tile "meshopt" gltf_ext/teapot-meshopt.gltf $C
tile "variants: default" gltf_ext/variants.gltf $C
tile "--variant green_left" gltf_ext/variants.gltf $C --variant green_left
sheet gltf-compression-variants.png 5
V="--camera frame --env $tmp/sky.exr --spp 128 --size 144x144"
tile "slab, index 1.5" volume/slab15.gltf $V
tile "liquid in glass" volume/nested.gltf $V
tile "touching media" volume/touching.gltf $V
D="--env 0 --spp 512 --size 144x144"
tile "glass, no dispersion" volume/nodisp.gltf $D
tile "dispersion 1 (Abbe 20)" volume/disp1.gltf $D
sheet gltf-volume.png 5
