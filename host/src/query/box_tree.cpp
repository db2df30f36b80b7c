#include "box_tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace bpaccel {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr unsigned kMortonBits = 10;  // per axis: 30-bit codes
constexpr std::size_t kSamples = 1024;

bool finite(float v) { return std::isfinite(v); }

// The centre of a box on one axis, in double so that no sum overflows; NaN when not finite.
double centre(const Aabb& b, int a) {
  const double c = 0.5 * (static_cast<double>(b.min[a]) + static_cast<double>(b.max[a]));
  return std::isfinite(c) ? c : std::numeric_limits<double>::quiet_NaN();
}

// Spreads the low 10 bits of v to every third bit.
std::uint32_t spread(std::uint32_t v) {
  v = (v | (v << 16)) & 0x030000FFu;
  v = (v | (v << 8)) & 0x0300F00Fu;
  v = (v | (v << 4)) & 0x030C30C3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

// The grid the centres are quantised on: from a sample of the centres, the
// range between the 1.5 % lowest and highest on each axis (a few far boxes,
// a ground plane, do not squeeze the others into one cell); centres outside
// it are clamped. The order only shapes the tree, never its answers.
struct Quantiser {
  std::array<double, 3> base{}, scale{};
  explicit Quantiser(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids) {
    const std::size_t n = ids.size(), step = std::max<std::size_t>(1, n / kSamples);
    std::vector<double> sample;
    for (int a = 0; a < 3; ++a) {
      sample.clear();
      for (std::size_t k = 0; k < n; k += step)
        if (const double c = centre(boxes[ids[k]], a); !std::isnan(c)) sample.push_back(c);
      if (sample.empty()) continue;
      std::sort(sample.begin(), sample.end());
      const std::size_t cut = sample.size() / 64;
      const double lo = sample[cut], hi = sample[sample.size() - 1 - cut];
      base[a] = lo;
      scale[a] = hi > lo ? static_cast<double>(1u << kMortonBits) / (hi - lo) : 0.0;
    }
  }
  std::uint32_t code(const Aabb& b) const {
    std::uint32_t code = 0;
    for (int a = 0; a < 3; ++a) {
      const double q = (centre(b, a) - base[a]) * scale[a];
      const std::uint32_t cell = !(q > 0) ? 0u : q >= (1u << kMortonBits) - 1 ? (1u << kMortonBits) - 1 : static_cast<std::uint32_t>(q);
      code |= spread(cell) << a;
    }
    return code;
  }
};

}  // namespace

bool BoxTree::walksTree(const RayQuery& ray) {
  for (int a = 0; a < 3; ++a) {
    const float inv = ray.inverseDirection[a];
    if (!finite(inv) || inv == 0.0f || ray.signs[a] != (inv < 0.0f ? 1u : 0u)) return false;
    if (!finite(ray.from[a]) || !finite(ray.grow.min[a]) || !finite(ray.grow.max[a])) return false;
    if (ray.grow.min[a] > ray.grow.max[a]) return false;
  }
  return true;
}

void BoxTree::build(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids) {
  nodes_.clear();
  leafNodes_ = 0;
  sortByMorton(boxes, ids);
  if (!ids_.empty()) buildLevels();
}

// A least-significant-digit radix sort of (code, position) on the code's 30 bits, 10 at a time.
void BoxTree::sortByMorton(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids) {
  const std::size_t n = ids.size();
  const Quantiser quantiser(boxes, ids);
  keys_.resize(n);
  scratch_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    keys_[k] = static_cast<std::uint64_t>(quantiser.code(boxes[ids[k]])) << 32 | k;
  constexpr std::size_t kBuckets = 1u << kMortonBits;
  std::array<std::size_t, kBuckets> start;
  for (unsigned shift = 32; shift < 32 + 3 * kMortonBits; shift += kMortonBits) {
    start.fill(0);
    for (const std::uint64_t key : keys_) ++start[(key >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (std::size_t& s : start) sum += std::exchange(s, sum);
    for (const std::uint64_t key : keys_) scratch_[start[(key >> shift) & (kBuckets - 1)]++] = key;
    keys_.swap(scratch_);
  }
  ids_.resize(n);
  sorted_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    ids_[k] = ids[keys_[k] & 0xFFFFFFFFu];
    sorted_[k] = boxes[ids_[k]];
  }
}

void BoxTree::buildLevels() {
  const auto emptyNode = [] {
    Node node;
    for (auto& axis : node.lo) axis.fill(kInf);
    for (auto& axis : node.hi) axis.fill(-kInf);
    node.child.fill(kEmpty);
    return node;
  };
  const std::size_t n = ids_.size();
  leafNodes_ = (n + 3) / 4;
  nodes_.reserve(leafNodes_ + leafNodes_ / 3 + 2);
  for (std::size_t j = 0; j < leafNodes_; ++j) {
    Node node = emptyNode();
    for (std::size_t l = 0; l < 4 && 4 * j + l < n; ++l) {
      const Aabb& b = sorted_[4 * j + l];
      for (int a = 0; a < 3; ++a) {
        node.lo[a][l] = b.min[a];
        node.hi[a][l] = b.max[a];
      }
      node.child[l] = static_cast<std::uint32_t>(4 * j + l);
      node.used |= 1u << l;
    }
    nodes_.push_back(node);
  }
  // Each level above: four consecutive nodes of the one below, each as the union of its lanes.
  std::size_t first = 0, count = leafNodes_;
  while (count > 1) {
    const std::size_t parents = (count + 3) / 4;
    for (std::size_t j = 0; j < parents; ++j) {
      Node node = emptyNode();
      for (std::size_t l = 0; l < 4 && 4 * j + l < count; ++l) {
        const std::size_t c = first + 4 * j + l;
        for (int a = 0; a < 3; ++a) {
          const auto& lo = nodes_[c].lo[a];
          const auto& hi = nodes_[c].hi[a];
          node.lo[a][l] = std::min(std::min(lo[0], lo[1]), std::min(lo[2], lo[3]));
          node.hi[a][l] = std::max(std::max(hi[0], hi[1]), std::max(hi[2], hi[3]));
        }
        node.child[l] = static_cast<std::uint32_t>(c);
        node.used |= 1u << l;
      }
      nodes_.push_back(node);
    }
    first += count;
    count = parents;
  }
}

}  // namespace bpaccel
