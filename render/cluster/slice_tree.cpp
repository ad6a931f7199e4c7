#include "render/cluster/slice_tree.h"

#include <algorithm>
#include <array>
#include <limits>
#include <tbb/parallel_for.h>

namespace vpl {

namespace {

using Point6 = std::array<float, 6>;

Point6 embed(const GatherPoint& g, float normalScale) {
  return {g.position.x, g.position.y, g.position.z,
          g.normal.x * normalScale, g.normal.y * normalScale, g.normal.z * normalScale};
}

float distance2(const Point6& a, const Point6& b) {
  float d = 0.0f;
  for (int k = 0; k < 6; ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
  return d;
}

struct Builder {
  const std::vector<Point6>& p;
  std::vector<uint32_t>& order;
  std::vector<Slice>& slices;
  uint32_t maxSize;

  void split(uint32_t begin, uint32_t end) {
    Point6 lo, hi;
    lo.fill(std::numeric_limits<float>::max());
    hi.fill(std::numeric_limits<float>::lowest());
    for (uint32_t i = begin; i < end; ++i)
      for (int k = 0; k < 6; ++k) {
        lo[k] = std::min(lo[k], p[order[i]][k]);
        hi[k] = std::max(hi[k], p[order[i]][k]);
      }
    if (end - begin <= maxSize) {
      leaf(begin, end);
      return;
    }
    // Split at the median position (not the spatial middle), which keeps the tree balanced. Points
    // that tie on the axis are ordered by the other axes, widest first, so a tie group divides along
    // a line in space. Divided by their place in the array instead, a level wall's rows (one y) or a
    // whole wall (x = 0) were cut into runs of rows, and a run that went with the other half joined
    // slices of other surfaces: thin dark lines in the preview, one per run.
    std::array<int, 6> axes{0, 1, 2, 3, 4, 5};
    std::stable_sort(axes.begin(), axes.end(), [&](int a, int b) { return hi[a] - lo[a] > hi[b] - lo[b]; });
    const auto before = [&](uint32_t a, uint32_t b) {
      for (int k : axes)
        if (p[a][k] != p[b][k]) return p[a][k] < p[b][k];
      return a < b;
    };
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end, before);
    split(begin, mid);
    split(mid, end);
  }

  void leaf(uint32_t begin, uint32_t end) {
    Point6 centroid{};
    for (uint32_t i = begin; i < end; ++i)
      for (int k = 0; k < 6; ++k) centroid[k] += p[order[i]][k];
    for (float& c : centroid) c /= float(end - begin);
    uint32_t best = order[begin];
    float bestD = std::numeric_limits<float>::max();
    for (uint32_t i = begin; i < end; ++i) {
      const float d = distance2(p[order[i]], centroid);
      if (d < bestD) {
        bestD = d;
        best = order[i];
      }
    }
    double spread = 0.0;
    for (uint32_t i = begin; i < end; ++i) spread += distance2(p[order[i]], p[best]);
    slices.push_back({begin, end, best, float(spread / double(end - begin))});
  }
};

}  // namespace

std::string SliceSettings::validate() const {
  if (maxSliceSize < 1) return "slice size must be at least 1";
  if (!(normalScale >= 0.0f)) return "normal scale must be non-negative";
  if (neighbours < 1) return "neighbour count must be at least 1";
  return {};
}

SliceTree buildSliceTree(std::span<const GatherPoint> points, const SliceSettings& settings, float sceneDiagonal) {
  SliceTree tree;
  tree.normalScale = settings.normalScale > 0.0f ? settings.normalScale : std::max(sceneDiagonal, 1e-30f) / 16.0f;
  const uint32_t n = uint32_t(points.size());
  std::vector<Point6> p(n);
  for (uint32_t i = 0; i < n; ++i) p[i] = embed(points[i], tree.normalScale);
  tree.order.resize(n);
  for (uint32_t i = 0; i < n; ++i) tree.order[i] = i;
  if (n > 0) Builder{p, tree.order, tree.slices, uint32_t(settings.maxSliceSize)}.split(0, n);

  tree.sliceOf.assign(n, 0);
  for (uint32_t s = 0; s < tree.slices.size(); ++s)
    for (uint32_t i = tree.slices[s].begin; i < tree.slices[s].end; ++i) tree.sliceOf[tree.order[i]] = s;

  // Nearest slices by representative, brute force: a few thousand slices at most.
  const uint32_t sliceCount = uint32_t(tree.slices.size());
  tree.neighbourCount = int(std::min<uint32_t>(uint32_t(settings.neighbours), sliceCount));
  tree.neighbours.resize(size_t(sliceCount) * size_t(tree.neighbourCount));
  tbb::parallel_for(uint32_t(0), sliceCount, [&](uint32_t s) {
    const Point6& r = p[tree.slices[s].representative];
    std::vector<std::pair<float, uint32_t>> d(sliceCount);
    for (uint32_t t = 0; t < sliceCount; ++t) d[t] = {t == s ? -1.0f : distance2(r, p[tree.slices[t].representative]), t};
    std::partial_sort(d.begin(), d.begin() + tree.neighbourCount, d.end());
    for (int k = 0; k < tree.neighbourCount; ++k) tree.neighbours[size_t(s) * tree.neighbourCount + size_t(k)] = d[size_t(k)].second;
  });
  return tree;
}

}  // namespace vpl
