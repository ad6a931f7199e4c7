// Range check of every index in a glTF file's JSON, before tinygltf's model is used. The model
// cannot be checked instead: tinygltf stores an explicit -1 as "absent", wraps 4294967296 to 0 and
// drops an index written as 1.5 or null, so only the raw JSON shows what the file says.
#pragma once
#include <cstddef>
#include <string>

namespace vpl::gltf {

// The JSON text of a .gltf, or the JSON chunk of a .glb (`binary`); throws InputError
// "<file>: nodes[0].mesh: -5 is not a mesh index" for the first index that is not an integer in
// range. Text that does not parse is left to tinygltf, whose message says why.
void checkIndices(const unsigned char* bytes, size_t size, bool binary, const std::string& file);

}  // namespace vpl::gltf
