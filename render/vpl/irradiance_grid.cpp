#include "render/vpl/irradiance_grid.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include "render/core/color.h"
#include "render/sampling/rng.h"
#include "render/vpl/vpl_tracer.h"

namespace vpl {

namespace {

// Coordinates count finest cells from the bounds' corner: at most kFinestCells across the diagonal,
// so 8 bits hold them, and a key (valid bit, level, side, three coordinates) fits in 32 bits.
constexpr int kCoordBits = 8;
constexpr uint32_t kCoordMax = (1u << kCoordBits) - 1u;
static_assert(IrradianceGrid::kFinestCells <= int(kCoordMax));

// Signed dominant axis of n: 0..5 for +x, -x, +y, -y, +z, -z.
uint32_t bucketOf(const glm::vec3& n) {
  const glm::vec3 a = glm::abs(n);
  const uint32_t axis = a.x >= a.y && a.x >= a.z ? 0u : (a.y >= a.z ? 1u : 2u);
  return 2u * axis + (n[int(axis)] < 0.0f ? 1u : 0u);
}

uint32_t packKey(int level, uint32_t bucket, glm::uvec3 c) {
  return 1u << 31 | uint32_t(level) << 27 | bucket << 24 | c.x << 16 | c.y << 8 | c.z;
}
glm::uvec3 coordsOf(uint32_t key) { return {(key >> 16) & kCoordMax, (key >> 8) & kCoordMax, key & kCoordMax}; }
int levelOf(uint32_t key) { return int(key >> 27) & 7; }
uint32_t bucketOfKey(uint32_t key) { return (key >> 24) & 7u; }

// Linear probing in a power-of-two table whose key at slot i is keyAt(i), 0 marking an empty slot:
// the slot that holds `key`, or the empty slot where the search for it ended. The table must have
// an empty slot.
template <class KeyAt>
size_t probe(uint32_t key, size_t tableSize, KeyAt keyAt) {
  const size_t mask = tableSize - 1;
  size_t i = size_t(mix64(key)) & mask;
  while (keyAt(i) != key && keyAt(i) != 0) i = (i + 1) & mask;
  return i;
}

}  // namespace

uint32_t IrradianceGrid::keyOf(const glm::vec3& p, const glm::vec3& n, int level) const {
  const glm::vec3 c = glm::floor((p - origin_) / (finestSize_ * float(1 << level)));
  const glm::vec3 clamped = glm::clamp(c, glm::vec3(0.0f), glm::vec3(float(kCoordMax)));
  return packKey(level, bucketOf(n), glm::uvec3(clamped));
}

int32_t IrradianceGrid::find(uint32_t key) const {
  if (keys_.empty()) return -1;
  const size_t i = probe(key, keys_.size(), [&](size_t j) { return keys_[j]; });
  return keys_[i] == key ? slots_[i] : -1;
}

IrradianceGrid::Cell& IrradianceGrid::insert(uint32_t key) {
  if (2 * (cells_.size() + 1) > keys_.size()) {  // keep the table at most half full
    std::vector<uint32_t> keys(std::max<size_t>(64, 2 * keys_.size()), 0);
    std::vector<int32_t> slots(keys.size(), -1);
    for (size_t j = 0; j < keys_.size(); ++j) {
      if (keys_[j] == 0) continue;
      const size_t i = probe(keys_[j], keys.size(), [&](size_t k) { return keys[k]; });
      keys[i] = keys_[j];
      slots[i] = slots_[j];
    }
    keys_ = std::move(keys);
    slots_ = std::move(slots);
  }
  const size_t i = probe(key, keys_.size(), [&](size_t j) { return keys_[j]; });
  if (keys_[i] == key) return cells_[size_t(slots_[i])];
  keys_[i] = key;
  slots_[i] = int32_t(cells_.size());
  Cell& c = cells_.emplace_back();
  c.key = key;
  return c;
}

void IrradianceGrid::splat(const std::vector<Vpl>& vpls, float weight) {
  for (const Vpl& v : vpls) {
    if (v.bounce == 0 || !isFiniteNonNegative(v.flux)) continue;
    totalFlux_ += weight * luminance(v.flux);
    // A VPL in a cell with no surface point has no area to spread over: rare slivers, dropped.
    const int32_t i = find(keyOf(v.position, v.normal, 0));
    if (i < 0) continue;
    cells_[size_t(i)].flux += weight * v.flux;
    ++cells_[size_t(i)].vpls;
  }
}

IrradianceGrid::IrradianceGrid(const RenderScene& scene, int photons, uint64_t seed, int pathDepth) {
  const SceneData& data = scene.data();
  origin_ = data.boundsMin - glm::vec3(1e-4f * scene.radius());
  finestSize_ = std::max(2.0f * scene.radius() / float(kFinestCells), 1e-20f);

  // Area of the finest cells, on both sides of every triangle: the centroids of a regular
  // subdivision into n^2 triangles whose edges are at most half a cell, each with 1/n^2 of the
  // area. Random points would do on average, but a cell's flux is divided by its area, and a noisy
  // divisor biases the quotient up.
  const float maxEdge = 0.5f * finestSize_;
  for (size_t m = 0; m < data.meshes.size(); ++m) {
    const MeshData& mesh = data.meshes[m];
    for (size_t t = 0; 3 * t + 2 < mesh.indices.size(); ++t) {
      const glm::vec3 p0 = mesh.positions[mesh.indices[3 * t]], p1 = mesh.positions[mesh.indices[3 * t + 1]],
                      p2 = mesh.positions[mesh.indices[3 * t + 2]];
      const glm::vec3 c = glm::cross(p1 - p0, p2 - p0);
      const float len = glm::length(c);
      const float area = 0.5f * len;
      if (!(area > 0.0f) || !std::isfinite(area)) continue;
      const float edge = std::max({glm::distance(p0, p1), glm::distance(p1, p2), glm::distance(p2, p0)});
      const int n = int(std::clamp(std::ceil(edge / maxEdge), 1.0f, 1024.0f));
      const glm::vec3 normal = c / len, e1 = (p1 - p0) / float(n), e2 = (p2 - p0) / float(n);
      const float subArea = area / float(n * n);
      const auto add = [&](float i, float j) {
        const glm::vec3 p = p0 + e1 * i + e2 * j;
        insert(keyOf(p, normal, 0)).area += subArea;
        insert(keyOf(p, -normal, 0)).area += subArea;
      };
      for (int i = 0; i < n; ++i)
        for (int j = 0; i + j < n; ++j) {
          add(float(i) + 1.0f / 3.0f, float(j) + 1.0f / 3.0f);
          if (i + j + 1 < n) add(float(i) + 2.0f / 3.0f, float(j) + 2.0f / 3.0f);
        }
    }
  }

  // Batches of VPLs, each normalised by its own light paths: their mean is the estimate.
  constexpr int kBatch = 1 << 16;
  const int batches = std::max(1, (photons + kBatch - 1) / kBatch);
  for (int b = 0; b < batches; ++b) {
    VplSettings batch = vplSettingsForPaths({}, pathDepth, mix64(seed ^ (0x6972726164ull + uint64_t(b))));
    batch.count = std::min(kBatch, std::max(1, photons));
    splat(traceVpls(scene, batch).vpls, 1.0f / float(batches));
  }

  // The coarser levels, each from the one below.
  size_t levelBegin = 0;
  for (int level = 1; level < kLevels; ++level) {
    const size_t levelEnd = cells_.size();
    for (size_t i = levelBegin; i < levelEnd; ++i) {
      const Cell child = cells_[i];
      Cell& parent = insert(packKey(level, bucketOfKey(child.key), coordsOf(child.key) / 2u));
      parent.area += child.area;
      parent.flux += child.flux;
      parent.vpls += child.vpls;
    }
    levelBegin = levelEnd;
  }

  // Resolve from the coarsest level down: a cell keeps its own estimate when its parent's VPLs,
  // shared out by area, promise it enough; else it takes its parent's. Deciding by its own count
  // would pick the cells whose count happened to come out high, and bias the estimate up.
  std::vector<glm::vec3> resolved(cells_.size(), glm::vec3(0.0f));
  for (size_t cell = cells_.size(); cell-- > 0;) {  // coarsest first: levels were made in order
    const Cell& c = cells_[cell];
    const int level = levelOf(c.key);
    const glm::vec3 own = c.area > 0.0f ? c.flux / c.area : glm::vec3(0.0f);
    const int32_t parent = level + 1 < kLevels ? find(packKey(level + 1, bucketOfKey(c.key), coordsOf(c.key) / 2u)) : -1;
    if (parent < 0) {
      resolved[cell] = own;
      continue;
    }
    const Cell& p = cells_[size_t(parent)];
    const float promised = p.area > 0.0f ? float(p.vpls) * c.area / p.area : 0.0f;
    resolved[cell] = promised >= float(kMinVpls) ? own : resolved[size_t(parent)];
  }
  // Filled to at most 2/3 (a hit rarely probes past its cache line).
  resolved_.assign(std::bit_ceil(std::max<size_t>(64, 3 * cells_.size() / 2)), Resolved{});
  for (size_t c = 0; c < cells_.size(); ++c)
    resolved_[probe(cells_[c].key, resolved_.size(), [&](size_t j) { return resolved_[j].key; })] = {cells_[c].key, resolved[c]};
  // The construction's tables are not needed by lookups.
  cellCount_ = cells_.size();
  keys_ = {};
  slots_ = {};
  cells_ = {};
}

glm::vec3 IrradianceGrid::irradiance(const glm::vec3& p, const glm::vec3& n) const {
  if (resolved_.empty()) return glm::vec3(0.0f);
  for (int level = 0; level < kLevels; ++level) {
    const uint32_t key = keyOf(p, n, level);
    const Resolved& r = resolved_[probe(key, resolved_.size(), [&](size_t j) { return resolved_[j].key; })];
    if (r.key == key) return r.irradiance;
  }
  return glm::vec3(0.0f);
}

size_t IrradianceGrid::memoryBytes() const {
  return keys_.capacity() * sizeof(uint32_t) + slots_.capacity() * sizeof(int32_t) + cells_.capacity() * sizeof(Cell) +
         resolved_.capacity() * sizeof(Resolved);
}

}  // namespace vpl
