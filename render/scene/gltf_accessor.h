// Checked reads of glTF accessors: every offset, stride and count is validated against its buffer
// view and buffer before a byte is read; sparse accessors are applied.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include <tiny_gltf.h>

namespace vpl::gltf {

// The accessor's elements as floats (normalized integers mapped to [0,1] / [-1,1]), count x
// components, row-major. `expectComponents` is checked; InputError names file and accessor.
std::vector<float> readFloats(const tinygltf::Model& model, int accessor, int expectComponents,
                              const std::string& file, uint64_t maxBytes);

// A scalar unsigned integer accessor (indices).
std::vector<uint32_t> readIndices(const tinygltf::Model& model, int accessor, const std::string& file,
                                  uint64_t maxBytes);

}  // namespace vpl::gltf
