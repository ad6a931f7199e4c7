#include "render/scene/gltf_validate.h"

#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include "render/core/error.h"

namespace vpl::gltf {

namespace {

using nlohmann::json;

// Every index property of glTF 2.0 (and of KHR_lights_punctual), checked against the length of the
// array it points into. Objects of the wrong type are skipped here: tinygltf reports those.
class IndexChecker {
 public:
  IndexChecker(const json& root, const std::string& file) : root_(root), file_(file) {}

  void run() {
    const size_t scenes = count(root_, "scenes"), nodes = count(root_, "nodes"), meshes = count(root_, "meshes"),
                 accessors = count(root_, "accessors"), textures = count(root_, "textures"),
                 views = count(root_, "bufferViews");
    index(root_, "scene", "", scenes, "a scene");
    each("scenes", [&](const json& s, const std::string& at) { indexArray(s, "nodes", at, nodes, "a node"); });
    const json* punctual = member(member(&root_, "extensions"), "KHR_lights_punctual");
    const size_t lights = punctual ? count(*punctual, "lights") : 0;
    each("nodes", [&](const json& n, const std::string& at) {
      index(n, "mesh", at, meshes, "a mesh");
      index(n, "camera", at, count(root_, "cameras"), "a camera");
      index(n, "skin", at, count(root_, "skins"), "a skin");
      indexArray(n, "children", at, nodes, "a node");
      if (const json* light = member(member(&n, "extensions"), "KHR_lights_punctual"))
        index(*light, "light", at + ".extensions.KHR_lights_punctual", lights, "a light");
    });
    each("meshes", [&](const json& m, const std::string& at) {
      eachOf(m, "primitives", at, [&](const json& p, const std::string& prim) {
        index(p, "indices", prim, accessors, "an accessor");
        index(p, "material", prim, count(root_, "materials"), "a material");
        allValues(p, "attributes", prim, accessors, "an accessor");
        eachOf(p, "targets", prim, [&](const json& t, const std::string& target) { allValues(t, "", target, accessors, "an accessor"); });
      });
    });
    each("materials", [&](const json& m, const std::string& at) {
      const json* pbr = member(&m, "pbrMetallicRoughness");
      textureInfo(pbr, "baseColorTexture", at + ".pbrMetallicRoughness", textures);
      textureInfo(pbr, "metallicRoughnessTexture", at + ".pbrMetallicRoughness", textures);
      for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) textureInfo(&m, key, at, textures);
      // Material extensions name their textureInfos "...Texture" (KHR_materials_specular,
      // _transmission, _clearcoat, ...): checked whether or not vplview reads the extension.
      if (const json* ext = member(&m, "extensions"); ext && ext->is_object())
        for (const auto& [name, e] : ext->items())
          if (e.is_object())
            for (auto it = e.begin(); it != e.end(); ++it)
              if (it.key().size() > 7 && it.key().compare(it.key().size() - 7, 7, "Texture") == 0)
                textureInfo(&e, it.key().c_str(), at + ".extensions." + name, textures);
    });
    each("textures", [&](const json& t, const std::string& at) {
      index(t, "source", at, count(root_, "images"), "an image");
      index(t, "sampler", at, count(root_, "samplers"), "a sampler");
    });
    each("images", [&](const json& i, const std::string& at) { index(i, "bufferView", at, views, "a bufferView"); });
    each("accessors", [&](const json& a, const std::string& at) {
      index(a, "bufferView", at, views, "a bufferView");
      const json* sparse = member(&a, "sparse");
      for (const char* part : {"indices", "values"})
        if (const json* p = member(sparse, part)) index(*p, "bufferView", at + ".sparse." + part, views, "a bufferView");
    });
    each("bufferViews", [&](const json& v, const std::string& at) {
      index(v, "buffer", at, count(root_, "buffers"), "a buffer");
      viewInsideBuffer(v, at);
    });
    each("skins", [&](const json& s, const std::string& at) {
      index(s, "inverseBindMatrices", at, accessors, "an accessor");
      index(s, "skeleton", at, nodes, "a node");
      indexArray(s, "joints", at, nodes, "a node");
    });
    each("animations", [&](const json& a, const std::string& at) {
      eachOf(a, "samplers", at, [&](const json& s, const std::string& sampler) {
        index(s, "input", sampler, accessors, "an accessor");
        index(s, "output", sampler, accessors, "an accessor");
      });
      eachOf(a, "channels", at, [&](const json& c, const std::string& channel) {
        index(c, "sampler", channel, count(a, "samplers"), "an animation sampler");
        if (const json* target = member(&c, "target")) index(*target, "node", channel + ".target", nodes, "a node");
      });
    });
  }

 private:
  static const json* member(const json* object, const char* key) {
    if (!object || !object->is_object()) return nullptr;
    const auto it = object->find(key);
    return it == object->end() ? nullptr : &*it;
  }
  static size_t count(const json& object, const char* key) {
    const json* a = member(&object, key);
    return a && a->is_array() ? a->size() : 0;
  }
  static std::string join(const std::string& at, const std::string& key) { return at.empty() ? key : at + "." + key; }

  template <class F>
  void eachOf(const json& object, const char* key, const std::string& at, F f) {
    const json* a = member(&object, key);
    if (!a || !a->is_array()) return;
    for (size_t i = 0; i < a->size(); ++i) f((*a)[i], join(at, key) + "[" + std::to_string(i) + "]");
  }
  template <class F>
  void each(const char* key, F f) { eachOf(root_, key, "", f); }

  // The property `key` of `object`, when present, must be an integer in [0, size).
  void index(const json& object, const char* key, const std::string& at, size_t size, const char* what) {
    if (const json* v = member(&object, key)) check(*v, join(at, key), size, what);
  }
  void indexArray(const json& object, const char* key, const std::string& at, size_t size, const char* what) {
    const json* a = member(&object, key);
    if (!a || !a->is_array()) return;
    for (size_t i = 0; i < a->size(); ++i) check((*a)[i], join(at, key) + "[" + std::to_string(i) + "]", size, what);
  }
  // Every value of an object of indices (attributes, morph targets); key "" is the object itself.
  void allValues(const json& object, const char* key, const std::string& at, size_t size, const char* what) {
    const json* o = *key ? member(&object, key) : &object;
    if (!o || !o->is_object()) return;
    const std::string base = *key ? join(at, key) : at;
    for (const auto& [name, v] : o->items()) check(v, join(base, name), size, what);
  }
  void textureInfo(const json* parent, const char* key, const std::string& at, size_t textures) {
    if (const json* info = member(parent, key)) index(*info, "index", join(at, key), textures, "a texture");
  }

  // A view's bytes must lie inside its buffer: tinygltf hands an image's view to the decoder
  // unchecked, and a view past a 114-byte buffer had stb_image read beyond it (found by
  // fuzz_gltf_loader, fuzz/regressions/image_view_past_buffer.glb).
  void viewInsideBuffer(const json& view, const std::string& at) {
    const json* buffers = member(&root_, "buffers");
    const json* b = member(&view, "buffer");
    const json* length = member(&view, "byteLength");
    const json* offset = member(&view, "byteOffset");
    if (!buffers || !buffers->is_array() || !b || !b->is_number_unsigned() || !length || !length->is_number_unsigned()) return;
    const json* bufferLength = member(&(*buffers)[b->get<size_t>()], "byteLength");
    if (!bufferLength || !bufferLength->is_number_unsigned()) return;
    const uint64_t start = offset && offset->is_number_unsigned() ? offset->get<uint64_t>() : 0;
    const uint64_t end = start + length->get<uint64_t>(), size = bufferLength->get<uint64_t>();
    if (end >= start && end <= size) return;
    throw InputError(file_ + ": " + at + ": bytes " + std::to_string(start) + " to " + std::to_string(end) + " run past buffer " +
                     std::to_string(b->get<size_t>()) + " (" + std::to_string(size) + " bytes)");
  }

  void check(const json& v, const std::string& path, size_t size, const char* what) {
    const bool ok = v.is_number_unsigned() ? v.get<uint64_t>() < size
                                           : v.is_number_integer() && v.get<int64_t>() >= 0 && uint64_t(v.get<int64_t>()) < size;
    if (ok) return;
    std::string value = v.dump(-1, ' ', false, json::error_handler_t::replace);
    if (value.size() > 40) value = value.substr(0, 37) + "...";
    throw InputError(file_ + ": " + path + ": " + value + " is not " + what + " index");
  }

  const json& root_;
  const std::string& file_;
};

uint32_t le32(const unsigned char* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

}  // namespace

void checkIndices(const unsigned char* bytes, size_t size, bool binary, const std::string& file) {
  const unsigned char* text = bytes;
  size_t length = size;
  if (binary) {
    // GLB: 12-byte header, then the JSON chunk (length, type "JSON", data). A broken header is
    // tinygltf's to report.
    if (size < 20 || le32(bytes + 16) != 0x4E4F534Au || le32(bytes + 12) > size - 20) return;
    text = bytes + 20;
    length = le32(bytes + 12);
  }
  const json root = json::parse(text, text + length, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded() || !root.is_object()) return;
  IndexChecker(root, file).run();
}

}  // namespace vpl::gltf
