#include "render/cluster/light_slice.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <queue>
#include <tbb/parallel_for.h>
#include "render/core/stopwatch.h"
#include "render/sampling/distribution_1d.h"
#include "render/sampling/rng.h"

namespace vpl {

std::string LightSliceSettings::validate() const {
  if (globalClusters < 1) return "global cluster count must be at least 1";
  if (clusterBudget < 1) return "cluster budget must be at least 1";
  if (reducedRows < 1) return "reduced matrix rows must be at least 1";
  if (refinementRows < 1) return "refinement rows must be at least 1";
  return {};
}

namespace {

// Light matrix columns restricted to some rows, stored column by column with their norms and unit
// vectors, so the clustering's inner loops read contiguous memory. Each column is padded with zeros
// to a multiple of four rows: the dot products then run four lanes at a time (a float reduction of
// unknown length is not vectorized without reassociation).
class Columns {
 public:
  Columns(std::span<const float* const> rows, uint32_t n)
      : stride_((rows.size() + 3) / 4 * 4), norms_(n), unit_(size_t(n) * stride_, 0.0f) {
    for (uint32_t j = 0; j < n; ++j) {
      float s = 0.0f;
      for (const float* r : rows) s += r[j] * r[j];
      norms_[j] = std::sqrt(s);
      const float inv = norms_[j] > 0.0f ? 1.0f / norms_[j] : 0.0f;
      for (size_t r = 0; r < rows.size(); ++r) unit_[size_t(j) * stride_ + r] = rows[r][j] * inv;
    }
  }
  float norm(uint32_t vpl) const { return norms_[vpl]; }
  const float* unit(uint32_t vpl) const { return &unit_[size_t(vpl) * stride_]; }
  float dot(const float* a, const float* b) const {
    float lane[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (size_t r = 0; r < stride_; r += 4)
      for (size_t l = 0; l < 4; ++l) lane[l] += a[r + l] * b[r + l];
    return (lane[0] + lane[1]) + (lane[2] + lane[3]);
  }
  // Cosine between two columns (1 when either is zero, so zero columns never drive a split).
  float cosine(uint32_t a, uint32_t b) const {
    if (norms_[a] <= 0.0f || norms_[b] <= 0.0f) return 1.0f;
    return dot(unit(a), unit(b));
  }
  // Matrix row-column sampling cost (Hašan et al. 2007, §4.1): sum over member pairs of
  // |x_i||x_j| |x_i/|x_i| - x_j/|x_j||^2 = 2 (sum |x_i|)^2 - 2 |sum x_i|^2. `sum` is scratch space.
  double cost(std::span<const uint32_t> members, std::vector<double>& sum) const {
    sum.assign(stride_, 0.0);
    double sumNorm = 0.0;
    for (uint32_t j : members) {
      const double w = norms_[j];
      if (w <= 0.0) continue;
      sumNorm += w;
      const float* u = unit(j);
      for (size_t r = 0; r < stride_; ++r) sum[r] += double(u[r]) * w;
    }
    double sum2 = 0.0;
    for (double v : sum) sum2 += v * v;
    return std::max(0.0, 2.0 * sumNorm * sumNorm - 2.0 * sum2);
  }

 private:
  size_t stride_;
  std::vector<float> norms_, unit_;
};

// What the per-slice loops read of every VPL, packed: the Vpl records are large, and walking them
// once per slice was memory-bound.
struct VplFigures {
  std::vector<glm::vec3> position, flux;
  std::vector<float> power;
  explicit VplFigures(std::span<const Vpl> vpls) : position(vpls.size()), flux(vpls.size()), power(vpls.size()) {
    for (size_t j = 0; j < vpls.size(); ++j) {
      position[j] = vpls[j].position;
      flux[j] = vpls[j].flux;
      power[j] = vpls[j].power();
    }
  }
};

// Orders `members` so that the first half lies below the median along the longest axis of their
// bounding box; returns the size of that half.
size_t halveInSpace(std::vector<uint32_t>& members, std::span<const glm::vec3> position) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (uint32_t j : members) {
    lo = glm::min(lo, position[j]);
    hi = glm::max(hi, position[j]);
  }
  const glm::vec3 ext = hi - lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const size_t mid = members.size() / 2;
  std::nth_element(members.begin(), members.begin() + std::ptrdiff_t(mid), members.end(),
                   [&](uint32_t a, uint32_t b) { return position[a][axis] < position[b][axis]; });
  return mid;
}

// Scratch space of one slice's refinement, reused across its splits.
struct SplitScratch {
  std::vector<float> norms;
  std::vector<uint32_t> rest;
  std::vector<double> sum;
};

// Two-way split of a cluster: pick two far-apart members in normalised column space and give every
// member to the nearer one; members that are zero on these rows go by VPL position.
bool splitCluster(const Columns& cols, std::span<const glm::vec3> position, const std::vector<uint32_t>& members,
                  std::vector<uint32_t>& left, std::vector<uint32_t>& right, SplitScratch& scratch) {
  if (members.size() < 2) return false;
  std::vector<float>& norms = scratch.norms;
  norms.resize(members.size());
  size_t pivot = 0;
  for (size_t i = 0; i < members.size(); ++i) {
    norms[i] = cols.norm(members[i]);
    if (norms[i] > norms[pivot]) pivot = i;
  }
  if (norms[pivot] <= 0.0f) pivot = 0;
  // The member least aligned with `from` (cosine 1 for zero columns, as Columns::cosine has it),
  // among at most kCandidates evenly strided members: the two poles need only be far apart, and a
  // full search on a cluster of thousands was most of the refinement's time.
  constexpr size_t kCandidates = 64;
  const size_t step = std::max<size_t>(1, members.size() / kCandidates);
  auto farthest = [&](size_t from) {
    size_t best = from;
    float bestCos = 2.0f;
    if (norms[from] <= 0.0f) return best;
    const float* u = cols.unit(members[from]);
    for (size_t i = 0; i < members.size(); i += step) {
      const float c = norms[i] > 0.0f ? cols.dot(u, cols.unit(members[i])) : 1.0f;
      if (c < bestCos) {
        bestCos = c;
        best = i;
      }
    }
    return best;
  };
  const size_t b = farthest(pivot), c = farthest(b);
  left.clear();
  right.clear();
  if (b != c && norms[b] > 0.0f && norms[c] > 0.0f) {
    const float *ub = cols.unit(members[b]), *uc = cols.unit(members[c]);
    for (size_t i = 0; i < members.size(); ++i) {
      if (norms[i] <= 0.0f) continue;
      const float* u = cols.unit(members[i]);
      (cols.dot(u, ub) >= cols.dot(u, uc) ? left : right).push_back(members[i]);
    }
  }
  // Zero columns, or columns all alike: split by position along the longest axis of the members.
  std::vector<uint32_t>& rest = scratch.rest;
  rest.clear();
  for (size_t i = 0; i < members.size(); ++i)
    if (norms[i] <= 0.0f || left.empty() || right.empty()) rest.push_back(members[i]);
  if (left.empty() || right.empty()) {
    left.clear();
    right.clear();
  }
  if (!rest.empty()) {
    const size_t mid = halveInSpace(rest, position);
    if (left.empty() && right.empty()) {
      left.assign(rest.begin(), rest.begin() + mid);
      right.assign(rest.begin() + mid, rest.end());
    } else {
      // Zero columns join the side whose first member is nearer in space.
      const glm::vec3 pl = position[left.front()], pr = position[right.front()];
      for (uint32_t j : rest)
        (glm::distance(position[j], pl) <= glm::distance(position[j], pr) ? left : right).push_back(j);
    }
  }
  return !left.empty() && !right.empty();
}

}  // namespace

LightSliceResult clusterLightSlice(std::span<const Vpl> vpls, std::span<const GatherPoint> points, const SliceTree& tree,
                                   const LightTransport& transport, const LightSliceSettings& settings,
                                   const std::atomic<bool>* cancel) {
  auto cancelled = [cancel] { return cancel && cancel->load(std::memory_order_relaxed); };
  LightSliceResult result;
  const uint32_t n = uint32_t(vpls.size()), sliceCount = uint32_t(tree.slices.size());
  result.slices.resize(sliceCount);
  if (n == 0 || sliceCount == 0) return result;
  std::atomic<uint64_t> evaluations{0};
  Stopwatch stopwatch;
  const VplFigures figures(vpls);

  // 1. Reduced light matrix: rows at evenly spread slices (a seeded stride through the slices).
  const uint32_t rowCount = std::min<uint32_t>(uint32_t(settings.reducedRows), sliceCount);
  std::vector<uint32_t> rowSlice(rowCount);
  Rng rowRng = Rng::hashed(mix64(settings.seed) ^ 0x726f7773ull);
  const double stride = double(sliceCount) / rowCount;
  for (uint32_t r = 0; r < rowCount; ++r)
    rowSlice[r] = std::min(sliceCount - 1, uint32_t((r + rowRng.uniform()) * stride));
  std::vector<float> matrix(size_t(rowCount) * n);
  tbb::parallel_for(uint32_t(0), rowCount * ((n + 1023) / 1024), [&](uint32_t task) {
    if (cancelled()) return;
    const uint32_t r = task % rowCount, j0 = (task / rowCount) * 1024, j1 = std::min(n, j0 + 1024);
    for (uint32_t j = j0; j < j1; ++j) matrix[size_t(r) * n + j] = transport.contribution(rowSlice[r], j, true);
    evaluations += j1 - j0;
  });
  result.matrixSeconds = stopwatch.lap();

  // 2. Global clustering over all reduced rows: seeds drawn by column norm, every column joins the
  //    seed it is most aligned with (MRCS's sampling clustering); columns that are zero in every
  //    sampled row join the seed nearest in space.
  std::vector<const float*> rowPointers(rowCount);
  for (uint32_t r = 0; r < rowCount; ++r) rowPointers[r] = &matrix[size_t(r) * n];
  const Columns global(rowPointers, n);
  std::vector<float> norms(n);
  for (uint32_t j = 0; j < n; ++j) norms[j] = global.norm(j);
  std::vector<uint32_t> seeds;
  {
    const Distribution1D byNorm(norms);
    Rng rng = Rng::hashed(mix64(settings.seed) ^ 0x73656564ull);
    std::vector<bool> taken(n, false);
    const int wanted = std::min(settings.globalClusters, settings.clusterBudget);
    for (int k = 0; k < 4 * wanted && int(seeds.size()) < wanted && !byNorm.empty(); ++k) {
      const uint32_t j = uint32_t(byNorm.sample(rng.uniform()));
      if (!taken[j]) {
        taken[j] = true;
        seeds.push_back(j);
      }
    }
    if (seeds.empty()) seeds.push_back(0);  // every column is zero: one cluster to start from
  }
  std::vector<uint32_t> globalOf(n, 0);
  tbb::parallel_for(uint32_t(0), n, [&](uint32_t j) {
    if (norms[j] <= 0.0f) {
      float nearest = INFINITY;
      for (uint32_t s = 0; s < seeds.size(); ++s) {
        const float d = glm::distance(figures.position[j], figures.position[seeds[s]]);
        if (d < nearest) {
          nearest = d;
          globalOf[j] = s;
        }
      }
      return;
    }
    float best = -2.0f;
    for (uint32_t s = 0; s < seeds.size(); ++s) {
      const float c = global.cosine(j, seeds[s]);
      if (c > best) {
        best = c;
        globalOf[j] = s;
      }
    }
  });
  std::vector<std::vector<uint32_t>> globalClusters(seeds.size());
  for (uint32_t j = 0; j < n; ++j) globalClusters[globalOf[j]].push_back(j);
  std::erase_if(globalClusters, [](const auto& c) { return c.empty(); });
  // Oversized global clusters (typically VPLs that no reduced row sees, gathered by position around a
  // few seeds) are halved in space until each holds at most four times the mean: every slice would
  // otherwise split them again, and their size set the refinement's cost.
  const size_t largest = std::max<size_t>(2, 4 * size_t(n) / size_t(std::max(1, settings.globalClusters)));
  for (size_t c = 0; c < globalClusters.size(); ++c) {
    while (globalClusters[c].size() > largest) {
      std::vector<uint32_t>& members = globalClusters[c];
      const auto mid = members.begin() + std::ptrdiff_t(halveInSpace(members, figures.position));
      std::vector<uint32_t> upper(mid, members.end());
      members.erase(mid, members.end());
      std::sort(members.begin(), members.end());  // index order: the per-slice loops walk memory forwards
      std::sort(upper.begin(), upper.end());
      globalClusters.push_back(std::move(upper));
    }
  }
  result.globalClusterCount = uint32_t(globalClusters.size());
  result.globalSeconds = stopwatch.lap();

  // 3. Per-slice refinement (LightSlice §4.2) on the slice's own row (its representative, unoccluded:
  //    one cheap evaluation per VPL) and the reduced rows nearest it (6D distance, with visibility).
  auto embedDistance = [&](uint32_t a, uint32_t b) { return embeddedDistance2(points[a], points[b], tree.normalScale); };
  const uint32_t k = std::min<uint32_t>(uint32_t(settings.refinementRows), rowCount);
  tbb::parallel_for(uint32_t(0), sliceCount, [&](uint32_t s) {
    if (cancelled()) return;
    const uint32_t rep = tree.slices[s].representative;
    std::vector<std::pair<float, uint32_t>> byDistance(rowCount);
    for (uint32_t r = 0; r < rowCount; ++r) byDistance[r] = {embedDistance(rep, tree.slices[rowSlice[r]].representative), r};
    std::partial_sort(byDistance.begin(), byDistance.begin() + k, byDistance.end());
    std::vector<float> ownRow(n);
    transport.unoccludedRow(s, ownRow);
    std::vector<const float*> localRows = {ownRow.data()};
    for (uint32_t i = 0; i < k; ++i) localRows.push_back(&matrix[size_t(byDistance[i].second) * n]);
    const Columns local(localRows, n);

    struct Entry {
      double cost;
      uint32_t index;
      bool operator<(const Entry& o) const { return cost < o.cost || (cost == o.cost && index > o.index); }
    };
    std::vector<std::vector<uint32_t>> clusters = globalClusters;
    SplitScratch scratch;
    std::priority_queue<Entry> queue;
    for (uint32_t c = 0; c < clusters.size(); ++c) queue.push({local.cost(clusters[c], scratch.sum), c});
    std::vector<uint32_t> left, right;
    while (int(clusters.size()) < settings.clusterBudget && !queue.empty()) {
      const Entry top = queue.top();
      queue.pop();
      if (top.cost <= 0.0 && clusters[top.index].size() < 2) continue;
      if (!splitCluster(local, figures.position, clusters[top.index], left, right, scratch)) continue;
      std::swap(clusters[top.index], left);
      clusters.push_back(right);
      queue.push({local.cost(clusters[top.index], scratch.sum), top.index});
      queue.push({local.cost(clusters.back(), scratch.sum), uint32_t(clusters.size() - 1)});
    }

    // Representatives by power, and their estimated contribution (with visibility) at this slice.
    SliceClusters& out = result.slices[s];
    out.clusters.resize(clusters.size());
    Rng rng = Rng::hashed(mix64(settings.seed ^ 0x636c7573ull) ^ s);  // hashed: per-slice streams must not share a state
    uint64_t evals = n;
    for (size_t c = 0; c < clusters.size(); ++c) {
      VplCluster& cl = out.clusters[c];
      const std::vector<uint32_t>& members = clusters[c];
      double total = 0.0;
      for (uint32_t j : members) {
        cl.totalFlux += figures.flux[j];
        total += std::max(0.0f, figures.power[j]);
      }
      cl.totalPower = float(total);
      // The representative by power: the member whose share of the running sum holds u x total.
      cl.representative = members[0];
      const float u = rng.uniform();
      if (total > 0.0) {
        const double target = double(u) * total;
        double running = 0.0;
        for (uint32_t j : members) {
          const float p = std::max(0.0f, figures.power[j]);
          if (p <= 0.0f) continue;
          cl.representative = j;
          running += p;
          if (running > target) break;
        }
        double spread2 = 0.0;
        const glm::vec3 centre = figures.position[cl.representative];
        for (uint32_t j : members) {
          const glm::vec3 d = figures.position[j] - centre;
          spread2 += double(std::max(0.0f, figures.power[j])) * glm::dot(d, d);
        }
        cl.spread = float(std::sqrt(spread2 / total));
      }
      const float repPower = figures.power[cl.representative];
      cl.estimate = repPower > 0.0f ? transport.contribution(s, cl.representative, true) * (cl.totalPower / repPower) : 0.0f;
      ++evals;
      if (settings.keepMembers) {
        cl.memberBegin = uint32_t(out.members.size());
        out.members.insert(out.members.end(), clusters[c].begin(), clusters[c].end());
        cl.memberEnd = uint32_t(out.members.size());
      }
    }
    evaluations += evals;
  });
  result.evaluations = evaluations.load();
  result.refineSeconds = stopwatch.lap();
  return result;
}

}  // namespace vpl
