#include "render/scene/gltf_loader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>
#include "render/core/error.h"
#include "render/scene/gltf_accessor.h"
#include "render/scene/gltf_image.h"
#include "render/scene/gltf_materials.h"
#include "render/scene/gltf_validate.h"

namespace vpl {

namespace fs = std::filesystem;

namespace {

const std::set<std::string> kSupportedExtensions = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                                    "KHR_materials_ior", "KHR_materials_specular"};

// What the file-system and image callbacks need: the folder a scene may read from, and the limits.
struct LoadContext {
  fs::path root;
  LoadLimits limits;
  std::string file;
  std::string firstError;  // set by callbacks; tinygltf's own message is less specific
};

bool insideRoot(const LoadContext& ctx, const std::string& path, fs::path& resolved) {
  std::error_code ec;
  resolved = fs::weakly_canonical(fs::path(path), ec);
  if (ec) return false;
  // Compare path components, so "/a/bc" is not inside "/a/b".
  auto r = ctx.root.begin();
  auto p = resolved.begin();
  for (; r != ctx.root.end(); ++r, ++p)
    if (p == resolved.end() || *p != *r) return false;
  return true;
}

bool fileExists(const std::string& path, void* user) {
  auto* ctx = static_cast<LoadContext*>(user);
  fs::path resolved;
  if (!insideRoot(*ctx, path, resolved)) {
    // tinygltf probes the scene's folder, then the working directory ("./" + uri). Judge the URI
    // itself, so a file merely missing from the folder stays tinygltf's "File not found".
    const std::string uri = path.rfind("./", 0) == 0 ? path.substr(2) : path;
    fs::path unused;
    if (ctx->firstError.empty() && (fs::path(uri).is_absolute() || !insideRoot(*ctx, (ctx->root / uri).string(), unused)))
      ctx->firstError = "'" + path + "' is outside the scene's folder: refused";
    return false;
  }
  std::error_code ec;
  return fs::is_regular_file(resolved, ec);
}

std::string expandPath(const std::string& path, void*) { return path; }

bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto* ctx = static_cast<LoadContext*>(user);
  fs::path resolved;
  auto fail = [&](const std::string& message) {
    if (ctx->firstError.empty()) ctx->firstError = message;
    if (err) *err += message;
    return false;
  };
  if (!insideRoot(*ctx, path, resolved))
    return fail("'" + path + "' is outside the scene's folder: refused");
  std::error_code ec;
  const auto size = fs::file_size(resolved, ec);
  if (ec) return fail("cannot read '" + path + "'");
  if (size > ctx->limits.maxBufferBytes) return fail("'" + path + "' is larger than the buffer limit");
  std::ifstream in(resolved, std::ios::binary);
  if (!in) return fail("cannot open '" + path + "'");
  out->resize(size);
  in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size));
  if (!in) return fail("cannot read '" + path + "'");
  return true;
}

bool writeWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed";
  return false;
}

// tinygltf's image callback: decodeImage (gltf_image.h) under the pixel limit; its refusal becomes
// the loader's first error.
bool loadImage(tinygltf::Image* image, const int index, std::string* err, std::string*, int, int,
               const unsigned char* bytes, int size, void* user) {
  auto* ctx = static_cast<LoadContext*>(user);
  try {
    gltf::DecodedImage decoded = gltf::decodeImage(bytes, size_t(std::max(size, 0)), ctx->limits.maxImagePixels, index);
    image->width = decoded.width;
    image->height = decoded.height;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image = std::move(decoded.rgba);
    return true;
  } catch (const InputError& e) {
    if (ctx->firstError.empty()) ctx->firstError = e.what();
    if (err) *err += e.what();
    return false;
  }
}

std::string firstLine(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

glm::mat4 localTransform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(node.matrix[size_t(i)]);  // column-major, as glTF
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(float(node.translation[0]), float(node.translation[1]), float(node.translation[2])));
  if (node.rotation.size() == 4) {
    glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]), float(node.rotation[2]));
    const float len = glm::length(q);
    if (len > 0.0f && std::isfinite(len)) m *= glm::mat4_cast(q / len);
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2])));
  return m;
}

class SceneBuilder {
 public:
  SceneBuilder(const tinygltf::Model& model, const std::string& file, const LoadLimits& limits)
      : model_(model), file_(file), limits_(limits), materials_(model, file_, scene_) {}

  SceneData build() {
    checkExtensions();
    std::vector<int> roots;
    const int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : (model_.scenes.empty() ? -1 : 0);
    if (sceneIndex >= 0) {
      if (size_t(sceneIndex) >= model_.scenes.size()) throw InputError(file_ + ": default scene does not exist");
      roots = model_.scenes[size_t(sceneIndex)].nodes;
    } else {
      // No scene: every node that is nobody's child is a root.
      std::vector<bool> child(model_.nodes.size(), false);
      for (const auto& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && size_t(c) < child.size()) child[size_t(c)] = true;
      for (size_t i = 0; i < child.size(); ++i)
        if (!child[i]) roots.push_back(int(i));
    }
    std::vector<int> onPath;
    for (int r : roots) visit(r, glm::mat4(1.0f), onPath, 0);
    if (degenerate_ > 0)
      scene_.notices.push_back(std::to_string(degenerate_) + " degenerate (zero-area) triangles skipped");
    // Valid, but most likely not what the author meant: say so rather than show an empty sky.
    if (scene_.meshes.empty()) scene_.notices.push_back("the scene instances no triangles: only the sky will be seen");
    if (scene_.materials.empty()) scene_.materials.push_back(Material{});
    computeBounds();
    return std::move(scene_);
  }

 private:
  void checkExtensions() {
    for (const std::string& e : model_.extensionsRequired)
      if (!kSupportedExtensions.count(e)) throw InputError(file_ + ": requires unsupported extension " + e);
    for (const std::string& e : model_.extensionsUsed)
      if (!kSupportedExtensions.count(e)) scene_.notices.push_back("extension " + e + " is ignored");
  }

  void visit(int index, const glm::mat4& parent, std::vector<int>& onPath, int depth) {
    if (index < 0 || size_t(index) >= model_.nodes.size())
      throw InputError(file_ + ": node " + std::to_string(index) + " does not exist");
    if (depth > 1024 || std::find(onPath.begin(), onPath.end(), index) != onPath.end())
      throw InputError(file_ + ": the node hierarchy has a cycle at node " + std::to_string(index));
    // Children may be shared, so a few nodes can stand for exponentially many instances.
    if (++visits_ > limits_.maxNodeVisits)
      throw InputError(file_ + ": the node hierarchy makes more than " + std::to_string(limits_.maxNodeVisits) +
                       " node instances, the limit");
    const tinygltf::Node& node = model_.nodes[size_t(index)];
    const glm::mat4 world = parent * localTransform(node);
    if (node.mesh >= 0) addMesh(node.mesh, world);
    if (node.camera >= 0 && !scene_.camera) addCamera(node.camera, world);
    if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end() && it->second.Has("light")) {
      // Not GetNumberAsInt: it casts any double to int unchecked (undefined behaviour past INT_MAX).
      const tinygltf::Value& light = it->second.Get("light");
      const double lightIndex = light.IsNumber() ? light.GetNumberAsDouble() : -1.0;
      if (!(lightIndex >= 0.0 && lightIndex < double(model_.lights.size())))
        throw InputError(file_ + ": node " + std::to_string(index) + " refers to a light that does not exist");
      addLight(int(lightIndex), world);
    }
    onPath.push_back(index);
    for (int c : node.children) visit(c, world, onPath, depth + 1);
    onPath.pop_back();
  }

  void addCamera(int index, const glm::mat4& world) {
    if (size_t(index) >= model_.cameras.size()) throw InputError(file_ + ": camera " + std::to_string(index) + " does not exist");
    const tinygltf::Camera& cam = model_.cameras[size_t(index)];
    if (cam.type != "perspective") return;
    CameraData c;
    c.eye = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    const glm::vec3 forward = glm::normalize(glm::mat3(world) * glm::vec3(0, 0, -1));
    c.up = glm::normalize(glm::mat3(world) * glm::vec3(0, 1, 0));
    c.target = c.eye + forward;
    c.yfov = float(cam.perspective.yfov);
    if (!(c.yfov > 0.0f && c.yfov < 3.14f) || !std::isfinite(c.eye.x + c.eye.y + c.eye.z + forward.x + forward.y + forward.z)) {
      scene_.notices.push_back("camera " + std::to_string(index) + " is invalid and was ignored");
      return;
    }
    if (cam.perspective.aspectRatio > 0.0) c.aspectRatio = float(cam.perspective.aspectRatio);
    scene_.camera = c;
  }

  void addLight(int index, const glm::mat4& world) {
    if (index < 0 || size_t(index) >= model_.lights.size())
      throw InputError(file_ + ": light " + std::to_string(index) + " does not exist");
    const tinygltf::Light& l = model_.lights[size_t(index)];
    PunctualLight p;
    if (l.type == "point") p.type = LightType::Point;
    else if (l.type == "spot") p.type = LightType::Spot;
    else if (l.type == "directional") p.type = LightType::Directional;
    else throw InputError(file_ + ": light " + std::to_string(index) + " has unknown type '" + l.type + "'");
    glm::vec3 color(1.0f);
    if (l.color.size() == 3) color = glm::vec3(float(l.color[0]), float(l.color[1]), float(l.color[2]));
    p.intensity = glm::max(color, glm::vec3(0.0f)) * std::max(0.0f, float(l.intensity));
    p.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
    p.direction = glm::normalize(glm::mat3(world) * glm::vec3(0, 0, -1));
    p.range = std::max(0.0f, float(l.range));
    if (p.type == LightType::Spot) {
      const float outer = std::clamp(float(l.spot.outerConeAngle), 0.0f, 1.5707963f);
      const float inner = std::clamp(float(l.spot.innerConeAngle), 0.0f, outer);
      p.cosOuter = std::cos(outer);
      p.cosInner = std::cos(inner);
    }
    const glm::vec3 check = p.intensity + p.position + p.direction;
    if (!std::isfinite(check.x + check.y + check.z))
      throw InputError(file_ + ": light " + std::to_string(index) + " has non-finite values");
    scene_.lights.push_back(p);
  }

  void addMesh(int meshIndex, const glm::mat4& world) {
    if (size_t(meshIndex) >= model_.meshes.size()) throw InputError(file_ + ": mesh " + std::to_string(meshIndex) + " does not exist");
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) addPrimitive(mesh, p, world);
  }

  void addPrimitive(const tinygltf::Mesh& mesh, size_t primIndex, const glm::mat4& world) {
    const tinygltf::Primitive& prim = mesh.primitives[primIndex];
    const std::string where = file_ + ": mesh '" + mesh.name + "' primitive " + std::to_string(primIndex);
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      scene_.notices.push_back("points and lines are not rendered (" + mesh.name + ")");
      return;
    }
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) {
      scene_.notices.push_back("a primitive without POSITION was skipped (" + mesh.name + ")");
      return;
    }
    const uint64_t maxBytes = limits_.maxBufferBytes;
    const std::vector<float> positions = gltf::readFloats(model_, pos->second, 3, file_, maxBytes);
    const size_t vertexCount = positions.size() / 3;

    MeshData out;
    out.name = mesh.name;
    out.positions.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) {
      const glm::vec3 p(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(where + ": position " + std::to_string(i) + " is not finite");
      out.positions[i] = glm::vec3(world * glm::vec4(p, 1.0f));
      if (!std::isfinite(out.positions[i].x + out.positions[i].y + out.positions[i].z))
        throw InputError(where + ": position " + std::to_string(i) + " overflows after the node transform");
    }
    if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      const std::vector<float> n = gltf::readFloats(model_, it->second, 3, file_, maxBytes);
      if (n.size() != positions.size()) throw InputError(where + ": NORMAL and POSITION counts differ");
      const glm::mat3 normalMatrix = glm::inverseTranspose(glm::mat3(world));
      out.normals.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) {
        const glm::vec3 v = normalMatrix * glm::vec3(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
        const float len = glm::length(v);
        out.normals[i] = (len > 0.0f && std::isfinite(len)) ? v / len : glm::vec3(0.0f);  // 0: use the geometric normal
      }
    }
    for (int set = 0; set < 2; ++set) {
      auto it = prim.attributes.find("TEXCOORD_" + std::to_string(set));
      if (it == prim.attributes.end()) continue;
      const std::vector<float> uv = gltf::readFloats(model_, it->second, 2, file_, maxBytes);
      if (uv.size() / 2 != vertexCount) throw InputError(where + ": TEXCOORD_" + std::to_string(set) + " and POSITION counts differ");
      auto& dst = set == 0 ? out.uvs0 : out.uvs1;
      dst.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i)
        dst[i] = glm::vec2(std::isfinite(uv[2 * i]) ? uv[2 * i] : 0.0f, std::isfinite(uv[2 * i + 1]) ? uv[2 * i + 1] : 0.0f);
    }

    std::vector<uint32_t> indices;
    if (prim.indices >= 0) {
      indices = gltf::readIndices(model_, prim.indices, file_, maxBytes);
      for (uint32_t i : indices)
        if (i >= vertexCount) throw InputError(where + ": index " + std::to_string(i) + " is out of range (" + std::to_string(vertexCount) + " vertices)");
    } else {
      indices.resize(vertexCount);
      for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
    }
    // A mirroring transform turns the winding around; undo it so front faces stay front faces.
    const bool flip = glm::determinant(glm::mat3(world)) < 0.0f;
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
      if (flip) std::swap(b, c);
      const glm::vec3 e = glm::cross(out.positions[b] - out.positions[a], out.positions[c] - out.positions[a]);
      const float area2 = glm::dot(e, e);
      if (!(area2 > 0.0f) || !std::isfinite(area2)) {
        ++degenerate_;
        return;
      }
      out.indices.insert(out.indices.end(), {a, b, c});
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (size_t i = 0; i + 2 < indices.size(); i += 3) emit(indices[i], indices[i + 1], indices[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < indices.size(); ++i)
        (i % 2 == 0) ? emit(indices[i], indices[i + 1], indices[i + 2]) : emit(indices[i + 1], indices[i], indices[i + 2]);
    } else {
      for (size_t i = 1; i + 1 < indices.size(); ++i) emit(indices[0], indices[i], indices[i + 1]);
    }
    triangles_ += out.indices.size() / 3;
    if (triangles_ > limits_.maxTriangles) throw InputError(file_ + ": more triangles than the limit");
    if (out.indices.empty()) return;
    out.material = materials_.material(prim.material);
    scene_.meshes.push_back(std::move(out));
  }

  void computeBounds() {
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (const MeshData& m : scene_.meshes)
      for (uint32_t i : m.indices) {
        lo = glm::min(lo, m.positions[i]);
        hi = glm::max(hi, m.positions[i]);
      }
    for (const PunctualLight& l : scene_.lights)
      if (l.type != LightType::Directional) {
        lo = glm::min(lo, l.position);
        hi = glm::max(hi, l.position);
      }
    if (lo.x > hi.x) lo = hi = glm::vec3(0.0f);
    scene_.boundsMin = lo;
    scene_.boundsMax = hi;
  }

  const tinygltf::Model& model_;
  std::string file_;
  LoadLimits limits_;
  SceneData scene_;
  gltf::MaterialConverter materials_;
  size_t degenerate_ = 0;
  uint64_t triangles_ = 0, visits_ = 0;
};

}  // namespace

SceneData loadGltf(const fs::path& path, const LoadLimits& limits) {
  const std::string file = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(file + ": no such file");
  if (!fs::is_regular_file(path, ec)) throw InputError(file + ": not a regular file");
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(file + ": cannot read");
  if (size > limits.maxBufferBytes) throw InputError(file + ": larger than the size limit");

  LoadContext ctx;
  ctx.root = fs::weakly_canonical(fs::absolute(path), ec).parent_path();
  ctx.limits = limits;
  ctx.file = file;

  // Read once, through the same checked callback tinygltf uses for the files the scene names.
  const std::string full = fs::absolute(path).string();
  std::vector<unsigned char> bytes;
  std::string err, warn;
  if (!readWholeFile(&bytes, &err, full, &ctx)) throw InputError(file + ": " + ctx.firstError);
  if (bytes.empty()) throw InputError(file + ": empty file");
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  gltf::checkIndices(bytes.data(), bytes.size(), binary, file);

  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({fileExists, expandPath, readWholeFile, writeWholeFile, &ctx});
  loader.SetImageLoader(loadImage, &ctx);
  tinygltf::Model model;
  const std::string baseDir = fs::path(full).parent_path().string();  // URIs resolve from here
  const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir)
                         : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                                      unsigned(bytes.size()), baseDir);
  if (!ok) {
    std::string why = !ctx.firstError.empty() ? ctx.firstError : firstLine(err);
    if (why.empty()) why = binary ? "not a valid GLB file" : "not a valid glTF file";
    throw InputError(file + ": " + why);
  }
  if (model.asset.version.rfind("2.", 0) != 0) throw InputError(file + ": glTF version '" + model.asset.version + "' is not 2.x");
  for (size_t b = 0; b < model.buffers.size(); ++b)
    if (model.buffers[b].data.size() > limits.maxBufferBytes) throw InputError(file + ": buffer " + std::to_string(b) + " exceeds the size limit");
  return SceneBuilder(model, file, limits).build();
}

}  // namespace vpl
