#include "render/scene/gltf_accessor.h"

#include <algorithm>
#include <cstring>
#include "render/core/error.h"

namespace vpl::gltf {

namespace {

int componentSize(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

int componentCount(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

// One component as a double; normalized integers follow glTF 2.0 §3.11 (signed: max(c / MAX, -1)).
double readComponent(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: { int8_t v; std::memcpy(&v, p, 1); return normalized ? std::max(v / 127.0, -1.0) : v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { uint8_t v; std::memcpy(&v, p, 1); return normalized ? v / 255.0 : v; }
    case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t v; std::memcpy(&v, p, 2); return normalized ? std::max(v / 32767.0, -1.0) : v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); return normalized ? v / 65535.0 : v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); return normalized ? v / 4294967295.0 : v; }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
    default: return 0.0;
  }
}

// The bytes of `count` elements of `elementSize` bytes in a buffer view, checked; returns base and stride.
struct ViewSpan {
  const unsigned char* base = nullptr;
  size_t stride = 0;
};

ViewSpan checkedView(const tinygltf::Model& model, int viewIndex, size_t byteOffset, size_t count, size_t elementSize,
                     bool allowStride, const std::string& where) {
  if (viewIndex < 0 || size_t(viewIndex) >= model.bufferViews.size())
    throw InputError(where + " refers to bufferView " + std::to_string(viewIndex) + ", which does not exist");
  const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    throw InputError(where + ": bufferView " + std::to_string(viewIndex) + " refers to a missing buffer");
  const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
  if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
    throw InputError(where + ": bufferView " + std::to_string(viewIndex) + " lies outside its buffer (" +
                     std::to_string(buffer.data.size()) + " bytes)");
  const size_t stride = (allowStride && view.byteStride > 0) ? view.byteStride : elementSize;
  if (stride < elementSize) throw InputError(where + ": byteStride is smaller than one element");
  if (count > 0) {
    // offset + stride * (count - 1) + elementSize <= byteLength, without overflow.
    if (byteOffset > view.byteLength || elementSize > view.byteLength - byteOffset ||
        (count - 1) > (view.byteLength - byteOffset - elementSize) / stride)
      throw InputError(where + ": " + std::to_string(count) + " elements do not fit in bufferView " +
                       std::to_string(viewIndex) + " (" + std::to_string(view.byteLength) + " bytes)");
  }
  return {buffer.data.data() + view.byteOffset + byteOffset, stride};
}

}  // namespace

std::vector<float> readFloats(const tinygltf::Model& model, int index, int expectComponents, const std::string& file,
                              uint64_t maxBytes) {
  const std::string where = file + ": accessor " + std::to_string(index);
  if (index < 0 || size_t(index) >= model.accessors.size()) throw InputError(where + " does not exist");
  const tinygltf::Accessor& a = model.accessors[size_t(index)];
  const int comps = componentCount(a.type), csize = componentSize(a.componentType);
  if (comps == 0 || csize == 0) throw InputError(where + " has an invalid type or componentType");
  if (comps != expectComponents)
    throw InputError(where + " has " + std::to_string(comps) + " components where " + std::to_string(expectComponents) +
                     " are required");
  if (uint64_t(a.count) * uint64_t(comps) * 4u > maxBytes)
    throw InputError(where + " claims " + std::to_string(a.count) + " elements, more than the size limit");

  // The view is checked before the output is allocated: a count the data cannot back costs nothing.
  const size_t elementSize = size_t(comps) * size_t(csize);
  ViewSpan span;
  if (a.bufferView >= 0) span = checkedView(model, a.bufferView, a.byteOffset, a.count, elementSize, true, where);
  std::vector<float> out(size_t(a.count) * size_t(comps), 0.0f);
  if (a.bufferView >= 0) {
    for (size_t i = 0; i < a.count; ++i)
      for (int c = 0; c < comps; ++c)
        out[i * comps + size_t(c)] = float(readComponent(span.base + i * span.stride + size_t(c) * csize, a.componentType, a.normalized));
  }
  if (a.sparse.isSparse) {
    // Sparse substitution (glTF 2.0 §3.6.2.3): indices select elements, values replace them.
    const size_t n = size_t(std::max(0, a.sparse.count));
    if (n > a.count) throw InputError(where + ": sparse count exceeds the accessor count");
    const int icsize = componentSize(a.sparse.indices.componentType);
    if (icsize == 0 || a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
      throw InputError(where + ": sparse indices have an invalid componentType");
    const ViewSpan idx = checkedView(model, a.sparse.indices.bufferView, size_t(std::max(0, a.sparse.indices.byteOffset)),
                                     n, size_t(icsize), false, where + " (sparse indices)");
    const ViewSpan val = checkedView(model, a.sparse.values.bufferView, size_t(std::max(0, a.sparse.values.byteOffset)),
                                     n, elementSize, false, where + " (sparse values)");
    for (size_t k = 0; k < n; ++k) {
      const double target = readComponent(idx.base + k * idx.stride, a.sparse.indices.componentType, false);
      if (!(target >= 0.0 && target < double(a.count))) throw InputError(where + ": sparse index out of range");
      for (int c = 0; c < comps; ++c)
        out[size_t(target) * comps + size_t(c)] =
            float(readComponent(val.base + k * val.stride + size_t(c) * csize, a.componentType, a.normalized));
    }
  }
  return out;
}

std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index, const std::string& file, uint64_t maxBytes) {
  const std::string where = file + ": index accessor " + std::to_string(index);
  if (index < 0 || size_t(index) >= model.accessors.size()) throw InputError(where + " does not exist");
  const tinygltf::Accessor& a = model.accessors[size_t(index)];
  if (a.type != TINYGLTF_TYPE_SCALAR) throw InputError(where + " is not SCALAR");
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    throw InputError(where + " must be unsigned byte, short or int");
  if (uint64_t(a.count) * 4u > maxBytes) throw InputError(where + " claims more elements than the size limit");
  if (a.sparse.isSparse) throw InputError(where + ": sparse index accessors are not supported");
  const int csize = componentSize(a.componentType);
  ViewSpan span;
  if (a.bufferView >= 0) span = checkedView(model, a.bufferView, a.byteOffset, a.count, size_t(csize), false, where);
  std::vector<uint32_t> out(a.count, 0u);
  if (a.bufferView >= 0) {
    for (size_t i = 0; i < a.count; ++i) out[i] = uint32_t(readComponent(span.base + i * span.stride, a.componentType, false));
  }
  return out;
}

}  // namespace vpl::gltf
