/* gltf_glb.cpp: binary glTF (.glb, glTF 2.0 specification section 4.4) through tinygltf's own
 * writer. gltf_write.c builds every document as JSON text with its buffer embedded; here
 * tinygltf parses that text and writes it again as GLB with the buffer as the BIN chunk. One
 * builder thus serves both formats, and the container (chunk headers, alignment, padding) is
 * tinygltf's, not a second hand-written one. No C++ exception escapes into C. */
#include <tiny_gltf.h>

#include <cstdio>
#include <exception>
#include <sstream>
#include <string>

extern "C" {
#include "gltf_write.h"
#include "util.h"
}

extern "C" bool gltf_write_glb_from_json(const char *path, const char *json, size_t len)
{
    try {
        tinygltf::TinyGLTF gltf;
        tinygltf::Model model;
        std::string err, warn;
        if (!gltf.LoadASCIIFromString(&model, &err, &warn, json, unsigned(len), "")) {
            util_error("%s: cannot convert the document to GLB: %s", path, err.c_str());
            return false;
        }
        /* A buffer without a uri is the one GLB stores in its BIN chunk. */
        if (!model.buffers.empty())
            model.buffers[0].uri.clear();
        std::ostringstream glb;
        if (!gltf.WriteGltfSceneToStream(&model, glb, false, true)) {
            util_error("%s: tinygltf could not write GLB", path);
            return false;
        }
        const std::string bytes = glb.str();
        util_out out;
        if (!util_out_open(&out, path))
            return false;
        FILE *f = util_out_file(&out);
        bool ok = f && fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
        if (f && !ok)
            util_error("%s: write failed (disk full?)", path);
        return util_out_commit(&out, ok);
    } catch (const std::exception &e) {
        util_error("%s: cannot write GLB: %s", path, e.what());
        return false;
    }
}
