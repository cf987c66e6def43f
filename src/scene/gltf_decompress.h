/* gltf_decompress.h: compressed glTF geometry turned into plain buffers (C++, for the loader).
 * KHR_draco_mesh_compression is decoded by Google's Draco library and EXT_meshopt_compression
 * by meshoptimizer; afterwards the model reads like an uncompressed one, so the loader's
 * checks and accessor reading see only ordinary buffers, views and accessors. */
#ifndef GONIO_GLTF_DECOMPRESS_H
#define GONIO_GLTF_DECOMPRESS_H

#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

/* Decodes every EXT_meshopt_compression buffer view into a new buffer the view then points
 * at, and every KHR_draco_mesh_compression primitive into new buffers its accessors then
 * read (float attributes, 32-bit indices). Returns false with one message per problem in
 * *errors (naming the buffer view or mesh primitive and what the decoder said); the model
 * may then be half rewritten and must not be read. max_elements bounds each decoded view or
 * accessor (the loader's per-accessor limit), and 16 x max_elements bytes all decoded data. */
bool gltf_decompress(tinygltf::Model &m, size_t max_elements, std::vector<std::string> *errors);

/* tinygltf 2.7 refuses an index accessor without a bufferView, which every Draco primitive
 * has, and reads a buffer without uri (a meshopt fallback buffer; in a GLB, one other than
 * buffer 0, the BIN chunk) as a file named "". Given
 * the JSON text, returns it with each such accessor pointed at its primitive's Draco
 * bufferView (gltf_decompress replaces it) and each such fallback buffer given one byte and
 * a mark, or "" when nothing needs that. */
std::string gltf_json_patch(const char *json, size_t len, bool glb);

#endif
