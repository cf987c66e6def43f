#!/usr/bin/env bash
# invalid.sh: malformed glTF. First `gonio render` over every glTF-Validator test case in
# $GONIO_ASSETS: a file whose validator report has an error in something gonio reads
# (the REJECT codes below) must fail (exit 1) with an error, other than "no triangles", that
# names the file, and write no output; one whose errors gonio degrades gracefully (the
# DEGRADE codes) must render with a warning, or fail naming the file after a warning. The
# valid controls must render, or fail only because they draw no triangle. Nothing may crash
# or hang. Then mutants of a valid scene, written here, one broken property each: each must
# be refused naming its JSON path (or, for the warnings, load and say so).
. "$(dirname "$0")/../lib.sh"
G=$GONIO
command -v python3 >/dev/null || skip_all "python3 is needed to read the reports and write the mutants"

# ---- the validator's corpus ------------------------------------------------------------
dir=${GONIO_ASSETS:-../shared/assets}/invalid-gltf
if [ ! -d "$dir" ]; then
    echo "  skipped: $dir is absent (the validator's corpus)"
else
# One line per case: FILE, its number of validator errors, and what gonio must do.
python3 - "$dir" >"$tmp/cases" <<'PY'
import json, os, sys
# Validator errors in what gonio reads: the file must be refused.
REJECT = {
    "INVALID_JSON", "TYPE_MISMATCH", "UNDEFINED_PROPERTY", "UNSATISFIED_DEPENDENCY", "UNUSED_EXTENSION_REQUIRED",
    "UNKNOWN_ASSET_MAJOR_VERSION", "IO_ERROR", "INVALID_URI", "VALUE_NOT_IN_RANGE", "VALUE_MULTIPLE_OF",
    "UNRESOLVED_REFERENCE", "BUFFER_BYTE_LENGTH_MISMATCH", "BUFFER_MISSING_GLB_DATA", "BUFFER_VIEW_TOO_LONG",
    "BUFFER_VIEW_TOO_BIG_BYTE_STRIDE", "BUFFER_VIEW_INVALID_BYTE_STRIDE", "ACCESSOR_OFFSET_ALIGNMENT",
    "ACCESSOR_TOTAL_OFFSET_ALIGNMENT", "ACCESSOR_TOO_LONG", "ACCESSOR_NORMALIZED_INVALID", "ACCESSOR_SMALL_BYTESTRIDE",
    "ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE", "ACCESSOR_INDEX_OOB", "ACCESSOR_INDEX_PRIMITIVE_RESTART",
    "MESH_PRIMITIVE_INDICES_ACCESSOR_INVALID_FORMAT", "MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_INVALID_FORMAT",
    "MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT", "NODE_LOOP",
}
# Errors gonio survives with a warning: bad values it clamps or skips (data it checks
# itself: non-finite or out-of-bounds elements, normals it renormalises, cameras, lights and
# images it skips), and a POSITION accessor without min/max (it computes the bounds).
DEGRADE = {
    "ACCESSOR_INVALID_FLOAT", "ACCESSOR_MIN_MISMATCH", "ACCESSOR_MAX_MISMATCH", "ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND",
    "ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND", "ACCESSOR_VECTOR3_NON_UNIT", "ACCESSOR_INVALID_SIGN",
    "CAMERA_ZFAR_LEQUAL_ZNEAR", "KHR_LIGHTS_PUNCTUAL_LIGHT_SPOT_ANGLES", "IMAGE_DATA_INVALID",
    "POSITION_ACCESSOR_WITHOUT_BOUNDS",
}
root = sys.argv[1]
for d, _, files in sorted(os.walk(root)):
    for f in sorted(files):
        if not f.endswith((".gltf", ".glb")) or not os.path.exists(os.path.join(d, f + ".report.json")):
            continue
        path = os.path.join(d, f)
        issues = json.load(open(path + ".report.json"))["issues"]
        kinds = set()
        for m in issues["messages"]:
            if m["severity"] != 0:
                continue
            code, ptr = m["code"], m.get("pointer", "")
            if code == "VALUE_NOT_IN_RANGE" and ptr.startswith("/materials/"):
                kinds.add("degrade")  # material factors are clamped with a warning
            elif code == "INVALID_JSON" and "BOM" in m["message"]:
                kinds.add("degrade")  # a byte order mark is skipped with a warning
            elif code in REJECT or code.startswith("GLB_"):  # the container gonio checks
                kinds.add("reject")
            elif code in DEGRADE:
                kinds.add("degrade")
            else:
                kinds.add("unclassified:" + code)
        kind = "valid" if not kinds else "reject" if "reject" in kinds else " ".join(sorted(kinds))
        print("%s\t%d\t%s" % (path, issues["numErrors"], kind))
PY
n=0
while IFS=$'\t' read -r f errors kind; do
    n=$((n + 1))
    out="$tmp/out-$n.exr"
    timeout 60 "$G" render "$f" -o "$out" --spp 1 --size 8x8 --quiet >"$tmp/log" 2>&1
    rc=$?
    base=$(basename "$f")
    # An error naming the file that is not just "no triangles" (which valid files give too).
    refused() { grep "error: .*$base" "$tmp/log" | grep -qv ': no triangles$'; }
    if [ $rc -ge 124 ]; then
        fail "$f: crashed or hung (exit $rc)"; sed 's/^/    /' "$tmp/log" | tail -n 5
    elif [ "$kind" = reject ]; then
        if [ $rc = 1 ] && refused && [ ! -e "$out" ]; then pass
        else fail "$f ($errors validator errors gonio must refuse): exit $rc"; sed 's/^/    /' "$tmp/log" | tail -n 5; fi
    elif [ "$kind" = degrade ]; then
        if [ $rc = 0 ] && grep -q "warning" "$tmp/log" && [ -s "$out" ]; then pass
        elif [ $rc = 1 ] && grep -qF "$base" "$tmp/log" && { grep -q "warning" "$tmp/log" || refused; } && [ ! -e "$out" ]; then pass
        else fail "$f ($errors validator errors gonio degrades): exit $rc"; sed 's/^/    /' "$tmp/log" | tail -n 5; fi
    elif [ "$kind" = valid ]; then
        if [ $rc = 0 ] || { [ $rc = 1 ] && grep -q "no triangles" "$tmp/log"; }; then pass
        else
            case "$base" in
            # An http:// buffer is valid glTF, but gonio reads no network resources.
            non_relative_uri.gltf) pass ;;
            # An unknown accessor type is only a validator warning, but no data can be read.
            unknown_type.gltf) pass ;;
            *) fail "$f (valid): exit $rc"; sed 's/^/    /' "$tmp/log" | tail -n 5 ;;
            esac
        fi
    else
        fail "$f: validator error codes this test does not classify: $kind"
    fi
    rm -f "$out"
done <"$tmp/cases"
[ $n -gt 50 ] || fail "only $n validator cases found"
fi

# ---- mutants: one broken property each -------------------------------------------------
# A valid scene that uses every property checked (buffer views with a stride, a texture with
# a sampler, a camera, a light, an animation, a child node and a node matrix), and from it
# one file per mutant. Manifest: NAME, the exit status wanted, a fragment of the message.
M=$tmp/mutants
mkdir -p "$M"
python3 - "$M" >"$M/list" <<'PY'
import base64, copy, json, sys
import gltf_fixture as gf
out = sys.argv[1]
g = gf.Gltf()
tri = [0, 0, 0, 1, 0, 0, 0, 1, 0]
strided = g.view(gf.pack(gf.FLOAT, tri), stride=12)
g.accessor(tri, "VEC3", view=strided, bounds=True)
g.accessor([0, 1, 2], "SCALAR", gf.UNSIGNED_SHORT)
keys = g.view(gf.pack(gf.FLOAT, [0, 1] + [0, 0, 0, 0, 0, 1]))  # an animation's key times, then its translations
g.accessor([0, 1], "SCALAR", view=keys, bounds=True)
g.accessor(None, "VEC3", view=keys, count=2, byteOffset=8)
sparse = {"count": 1, "indices": {"bufferView": g.view(gf.pack(gf.UNSIGNED_SHORT, [1])), "componentType": gf.UNSIGNED_SHORT},
          "values": {"bufferView": g.view(gf.pack(gf.FLOAT, [1, 0, 0])), "byteOffset": 0}}
g.accessor(tri, "VEC3", view=strided, bounds=True, sparse=sparse)
png = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAABJRU5ErkJggg==")
g.texture(g.image(png), g.sampler(mag=gf.LINEAR, min=9987, wrap=[gf.REPEAT, gf.CLAMP_TO_EDGE]))
g.material({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 0}}, "alphaMode": "OPAQUE"})
g.mesh({"attributes": {"POSITION": 0}, "indices": 1, "material": 0, "mode": 4})
g.mesh({"attributes": {"POSITION": 4}})
g.node(mesh=0, children=[1, 2])
g.node(camera=g.perspective(0.8, 0.1), translation=[0.3, 0.3, 3])
g.node(matrix=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 2, 0, 0, 1], mesh=1, light=g.light("point", intensity=1))
g.add("animations", {"samplers": [{"input": 2, "output": 3, "interpolation": "LINEAR"}],
                     "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]})
g.scene([0])
g.write(out + "/base.gltf")
base = g.doc
# NAME, JSON path (a list of keys), the new value (DELETE removes it), exit status wanted,
# a fragment of the error (of the warning when the status is 0) wanted.
DELETE = object()
mutants = [
    # Indices that tinygltf wrapped, rounded or dropped.
    ("buffer_2p32", ["bufferViews", 0, "buffer"], 4294967296, 1, "bufferViews[0].buffer: 4294967296 does not exist"),
    ("material_1e20", ["meshes", 0, "primitives", 0, "material"], 1e20, 1,
     "meshes[0].primitives[0].material: 1e+20 is not an integer index"),
    ("material_2p32", ["meshes", 0, "primitives", 0, "material"], 2**32, 1, "material: 4294967296 does not exist"),
    ("child_fraction", ["nodes", 0, "children", 0], 1.5, 1, "nodes[0].children[0]: 1.5 is not an integer index"),
    ("child_negative", ["nodes", 0, "children", 1], -1, 1, "nodes[0].children[1]: -1 is not a valid index"),
    ("mesh_float", ["nodes", 0, "mesh"], 0.0, 1, "nodes[0].mesh: 0.0 is not an integer index"),
    ("mesh_string", ["nodes", 0, "mesh"], "0", 1, "nodes[0].mesh: \"0\" is not an integer index"),
    ("camera_range", ["nodes", 1, "camera"], 1, 1, "nodes[1].camera: 1 does not exist (cameras has 1 entry)"),
    ("skin_fraction", ["nodes", 0, "skin"], 0.5, 1, "nodes[0].skin: 0.5 is not an integer index"),
    ("light_fraction", ["nodes", 2, "extensions", "KHR_lights_punctual", "light"], 0.5, 1,
     "nodes[2].extensions.KHR_lights_punctual.light: 0.5 is not an integer index"),
    ("accessor_2p32", ["meshes", 0, "primitives", 0, "attributes", "POSITION"], 2**32 + 0, 1,
     "attributes.POSITION: 4294967296 does not exist"),
    ("indices_1e20", ["meshes", 0, "primitives", 0, "indices"], 1e20, 1, "indices: 1e+20 is not an integer index"),
    ("view_fraction", ["accessors", 0, "bufferView"], 0.5, 1, "accessors[0].bufferView: 0.5 is not an integer index"),
    ("texture_1e20", ["materials", 0, "pbrMetallicRoughness", "baseColorTexture", "index"], 1e20, 1,
     "baseColorTexture.index: 1e+20 is not an integer index"),
    ("sampler_2p32", ["textures", 0, "sampler"], 2**32, 1, "textures[0].sampler: 4294967296 does not exist"),
    ("source_fraction", ["textures", 0, "source"], 0.5, 1, "textures[0].source: 0.5 is not an integer index"),
    ("scene_2p32", ["scene"], 2**32, 1, "scene: 4294967296 does not exist"),
    ("scene_node_fraction", ["scenes", 0, "nodes", 0], 0.5, 1, "scenes[0].nodes[0]: 0.5 is not an integer index"),
    ("anim_sampler", ["animations", 0, "channels", 0, "sampler"], 2**32, 1,
     "animations[0].channels[0].sampler: 4294967296 does not exist"),
    ("anim_node", ["animations", 0, "channels", 0, "target", "node"], 1.5, 1, "target.node: 1.5 is not an integer index"),
    ("anim_input", ["animations", 0, "samplers", 0, "input"], -2, 1, "samplers[0].input: -2 is not a valid index"),
    ("attribute_key", ["meshes", 0, "primitives", 0, "attributes", "TEXCOORD_\n9"], 99, 1,
     "attributes.TEXCOORD_?9: 99 does not exist"),  # a control character in a message
    ("sparse_view", ["accessors", 4, "sparse", "values", "bufferView"], 2**32 + 4, 1,
     "sparse.values.bufferView: 4294967300 does not exist"),
    # Sizes and offsets: non-negative integers in range.
    ("offset_negative", ["accessors", 3, "byteOffset"], -12, 1, "accessors[3].byteOffset: -12 is out of range"),
    ("view_offset_negative", ["bufferViews", 1, "byteOffset"], -12, 1, "bufferViews[1].byteOffset: -12 is out of range"),
    ("stride_negative", ["bufferViews", 0, "byteStride"], -4, 1, "bufferViews[0].byteStride: -4 is out of range"),
    ("stride_big", ["bufferViews", 0, "byteStride"], 256, 1, "bufferViews[0].byteStride: 256 is out of range (4..252)"),
    ("stride_multiple", ["bufferViews", 0, "byteStride"], 14, 1, "bufferViews[0].byteStride: 14 is not a multiple of 4"),
    ("stride_fraction", ["bufferViews", 0, "byteStride"], 12.5, 1, "bufferViews[0].byteStride: 12.5 is not an integer"),
    ("view_length_zero", ["bufferViews", 1, "byteLength"], 0, 1, "bufferViews[1].byteLength: 0 is out of range"),
    ("buffer_length_float", ["buffers", 0, "byteLength"], 1e20, 1, "buffers[0].byteLength: 1e+20 is not an integer"),
    ("count_zero", ["accessors", 0, "count"], 0, 1, "accessors[0].count: 0 is out of range"),
    ("count_negative", ["accessors", 1, "count"], -3, 1, "accessors[1].count: -3 is out of range"),
    ("count_string", ["accessors", 1, "count"], "3", 1, "accessors[1].count: \"3\" is not an integer"),
    ("count_missing", ["accessors", 1, "count"], DELETE, 1, "accessors[1].count: missing (required)"),
    ("sparse_offset_negative", ["accessors", 4, "sparse", "values", "byteOffset"], -4, 1,
     "sparse.values.byteOffset: -4 is out of range"),
    ("sparse_count_big", ["accessors", 4, "sparse", "count"], 3000000000, 1,
     "sparse.count: 3000000000 is out of range (1..2147483647)"),
    ("texcoord_negative", ["materials", 0, "pbrMetallicRoughness", "baseColorTexture", "texCoord"], -1, 1,
     "baseColorTexture.texCoord: -1 is out of range"),
    ("offset_without_view", ["accessors", 3, "bufferView"], DELETE, 1, "accessors[3].byteOffset: requires a bufferView"),
    # Enums.
    ("component_type", ["accessors", 0, "componentType"], 5124, 1, "accessors[0].componentType: 5124 is not one of"),
    ("accessor_type", ["accessors", 0, "type"], "VEC5", 1, "accessors[0].type: \"VEC5\" is not one of"),
    ("mode", ["meshes", 0, "primitives", 0, "mode"], 7, 1, "meshes[0].primitives[0].mode: 7 is not one of"),
    ("alpha_mode", ["materials", 0, "alphaMode"], "GLASS", 1, "materials[0].alphaMode: \"GLASS\" is not one of"),
    ("mag_filter", ["samplers", 0, "magFilter"], 9987, 1, "samplers[0].magFilter: 9987 is not one of"),
    ("min_filter", ["samplers", 0, "minFilter"], 1, 1, "samplers[0].minFilter: 1 is not one of"),
    ("wrap_s", ["samplers", 0, "wrapS"], 0, 1, "samplers[0].wrapS: 0 is not one of"),
    ("wrap_t", ["samplers", 0, "wrapT"], 10497.5, 1, "samplers[0].wrapT: 10497.5 is not one of"),
    ("camera_type", ["cameras", 0, "type"], "fisheye", 1, "cameras[0].type: \"fisheye\" is not one of"),
    ("anim_path", ["animations", 0, "channels", 0, "target", "path"], "color", 1, "target.path: \"color\" is not one of"),
    # Node matrices must be affine (elements 3, 7, 11 = 0 and 15 = 1, column-major).
    ("matrix_projective", ["nodes", 2, "matrix", 3], 0.5, 1, "nodes[2].matrix: is not affine"),
    ("matrix_projective_w", ["nodes", 2, "matrix", 15], 2, 1, "nodes[2].matrix: is not affine"),
    ("matrix_projective_11", ["nodes", 2, "matrix", 11], -0.25, 1, "nodes[2].matrix: is not affine"),
    ("matrix_rounding", ["nodes", 2, "matrix", 15], 1 + 1e-9, 0, ""),
    ("matrix_string", ["nodes", 2, "matrix", 0], "1", 1, "nodes[2].matrix[0]: \"1\" is not a number"),
    # Wrong JSON types.
    ("nodes_object", ["nodes"], {}, 1, "nodes: {} is not an array"),
    ("node_array", ["nodes", 1], [], 1, "nodes[1]: [] is not an object"),
    ("normalized_string", ["accessors", 1, "normalized"], "false", 1, "accessors[1].normalized: \"false\" is not true or false"),
    # POSITION bounds: required by glTF, a warning here (gonio computes them itself), and
    # when present they must bound the data (a warning too).
    ("position_no_min", ["accessors", 0, "min"], DELETE, 0, "accessors[0]: a POSITION accessor without min and max"),
    ("position_no_max", ["accessors", 4, "max"], DELETE, 0, "accessors[4]: a POSITION accessor without min and max"),
    ("position_max_low", ["accessors", 0, "max", 0], 0.5, 0, "accessor 0: element 1 (1) lies outside its declared min/max"),
]
def put(doc, path, value):
    for k in path[:-1]:
        doc = doc[k]
    if value is DELETE:
        del doc[path[-1]]
    else:
        doc[path[-1]] = value
print("base\t0\t")
for name, path, value, rc, msg in mutants:
    doc = copy.deepcopy(base)
    put(doc, path, value)
    text = json.dumps(doc)
    if name == "buffer_length_float":
        text = text.replace("1e+20", "1e20")  # as a fuzzer writes it
    open("%s/%s.gltf" % (out, name), "w").write(text)
    print("%s\t%d\t%s" % (name, rc, msg))
PY
nm=0
while IFS=$'\t' read -r mut want msg; do
    nm=$((nm + 1))
    f="$M/$mut.gltf"
    timeout 60 "$G" info "$f" >"$tmp/log" 2>&1
    rc=$?
    if [ "$rc" != "$want" ]; then
        fail "mutant $mut: exit $rc, expected $want"; sed 's/^/    /' "$tmp/log" | grep gonio: | tail -n 3
    elif [ "$mut" = base ] && grep -q "warning\|error" "$tmp/log"; then
        fail "the mutants' base scene loads with a message"; sed 's/^/    /' "$tmp/log" | grep gonio: | tail -n 3
    elif [ -n "$msg" ] && ! grep "$([ "$want" = 0 ] && echo warning || echo error): $f: " "$tmp/log" | grep -qF -- "$msg"; then
        fail "mutant $mut: no $([ "$want" = 0 ] && echo warning || echo error) naming the file with '$msg'"
        sed 's/^/    /' "$tmp/log" | grep gonio: | tail -n 3
    else
        pass
    fi
done <"$M/list"
[ $nm -gt 50 ] || fail "only $nm mutants written"
# Rendered, a refused file writes no output.
check_fails "render refuses a mutant" 1 "$G" render "$M/child_fraction.gltf" -o "$tmp/mutant.exr" --spp 1 --size 8x8 --quiet
check "... writing no output" test ! -e "$tmp/mutant.exr"
check "... naming the JSON path" grep -qF "nodes[0].children[0]: 1.5 is not an integer index" "$tmp/last"
finish
