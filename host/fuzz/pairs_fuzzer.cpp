// The pair-finding API on any scene decoded from the bytes: BroadPhase with
// the cpu and the model backend, with and without a k-d tree, and with a
// uniform grid (same cell size; it may hand the scene to the tree), returns exactly
// the pairs of a brute-force test on the floats, each once. Scenes mix
// infinities, denormals, signed zeros, float extremes, a coarse integer grid
// (touching faces), raw float bits and repeated boxes. The model runs with a
// small m and capacity taken from the input, so cells are chunked often, and
// on one or two threads.
// A NaN coordinate must be refused with an InputError naming its box.
//
// Input layout (read front to back; missing bytes read as 0), so seeds can be
// written by hand (host/fuzz/README.md):
//   cell byte: 0 = no partition, else cell size 1 + (byte - 1) % 40 (k-d tree and grid)
//   and the model's key width 32, 16, 4 or 1 by ((byte - 1) / 40) % 4 (no partition: 32)
//   m byte: model lanes 1 + byte % 8; bits 3-4: the model's cells per hand-over
//   1 + 3 * bits (1, 4, 7, 10); bits 5-6: its hardware batch 1 + bits cells
//   (a hand-over beyond it is split); with bit 7 set the model with the k-d
//   tree also runs on 2 threads;  capacity byte: m * (1 + byte % (24/m + 1)), at least 2
//   then records: op byte < 0x30 repeats an earlier box (op % count),
//   any other op is followed by a box: per axis two coordinates, sorted.
//   Coordinate byte k: k < 0x60 special value kSpecial[k % 24],
//   k < 0xe0 grid value (k - 0x60) % 9 - 4, else 4 raw little-endian bytes.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <limits>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "device/model_backend.hpp"
#include "device/cpu_backend.hpp"
#include "device/backend.hpp"
#include "broad_phase/broad_phase.hpp"
#include "fuzz_check.hpp"
#include "core/keys.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using bpaccel::fuzz::require;

namespace {

constexpr std::size_t kMaxBoxes = 96;  // chunking at capacity 2 runs n^2/2 times

// Values where float order, key order and the zero/infinity/denormal rules
// meet: a coordinate often lands exactly on another box's face.
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kDenormMin = std::numeric_limits<float>::denorm_min();
constexpr float kNormMin = std::numeric_limits<float>::min();
constexpr float kMax = std::numeric_limits<float>::max();
constexpr float kLargestDenorm = kNormMin - kDenormMin;
constexpr float kSpecial[] = {-kInf, kInf, -0.0f, 0.0f, kDenormMin, -kDenormMin, 2 * kDenormMin, -2 * kDenormMin,
                              kLargestDenorm, -kLargestDenorm, kNormMin, -kNormMin, kMax, -kMax, 1.0f, -1.0f,
                              0.5f, 1.0000001f, 0.99999994f, 3e38f, -3e38f, 1e-38f, -1e-38f, 16777216.0f};

// The fuzzer's bytes, read front to back; past the end every byte is 0.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  std::uint8_t byte() { return empty() ? 0 : data_[pos_++]; }
  std::uint32_t word() {
    std::uint32_t w = 0;
    for (int shift = 0; shift < 32; shift += 8) w |= std::uint32_t{byte()} << shift;
    return w;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

float coordinate(ByteReader& in) {
  const std::uint8_t kind = in.byte();
  if (kind < 0x60) return kSpecial[kind % std::size(kSpecial)];
  if (kind < 0xe0) return static_cast<float>((kind - 0x60) % 9 - 4);  // a coarse grid: faces touch
  return std::bit_cast<float>(in.word());                            // anything, NaN included
}

Aabb decodeBox(ByteReader& in) {
  Aabb b{};
  for (int a = 0; a < 3; ++a) {
    const float x = coordinate(in), y = coordinate(in);
    // Ordered so min <= max; equal values (such as -0 and +0) keep the order
    // they came in, so both zero orders occur. NaN stays where it fell.
    const bool swap = y < x;
    b.min[a] = swap ? y : x;
    b.max[a] = swap ? x : y;
  }
  return b;
}

std::vector<Aabb> decodeScene(ByteReader& in) {
  std::vector<Aabb> boxes;
  while (!in.empty() && boxes.size() < kMaxBoxes) {
    const std::uint8_t op = in.byte();
    if (op < 0x30 && !boxes.empty())
      boxes.push_back(boxes[op % boxes.size()]);  // an identical box
    else
      boxes.push_back(decodeBox(in));
  }
  return boxes;
}

std::optional<std::size_t> firstBoxWithNaN(const std::vector<Aabb>& boxes) {
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (std::isnan(boxes[i].min[a]) || std::isnan(boxes[i].max[a])) return i;
  return std::nullopt;
}

// One configuration under test: a backend, a cell size and a thread count.
struct Setup {
  std::string label;
  std::function<std::unique_ptr<BroadPhase>()> make;
};

// The reference pairs as an n x n table, so checking a result costs one look-up
// a pair (no sort: the long run spends its time on scenes, not on checking).
class ExpectedPairs {
 public:
  explicit ExpectedPairs(const std::vector<Aabb>& boxes) : n_(boxes.size()), table_(n_ * n_) {
    const std::vector<Pair> pairs = testing::bruteForce(boxes);
    for (const auto& [i, j] : pairs) table_[i * n_ + j] = 1;
    count_ = pairs.size();
  }
  std::size_t size() const { return n_; }
  std::size_t count() const { return count_; }
  bool contains(std::size_t i, std::size_t j) const { return table_[i * n_ + j] != 0; }

 private:
  std::size_t n_;
  std::vector<std::uint8_t> table_;
  std::size_t count_ = 0;
};

void checkExact(const Setup& setup, const std::vector<Aabb>& boxes, const ExpectedPairs& expected) {
  const auto broadPhase = setup.make();
  std::vector<Pair> pairs;
  broadPhase->findPairs(boxes, pairs);
  const std::size_t n = boxes.size();
  std::vector<std::uint8_t> seen(n * n);
  for (const auto& [i, j] : pairs) {
    require(i < j && j < n, "{}: bad pair ({}, {})", setup.label, i, j);
    require(expected.contains(i, j), "{}: ({}, {}) do not overlap", setup.label, i, j);
    require(!seen[i * n + j], "{}: ({}, {}) reported twice", setup.label, i, j);
    seen[i * n + j] = 1;
  }
  if (pairs.size() == expected.count()) return;  // every reported pair expected, none twice: all found
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      require(!expected.contains(i, j) || seen[i * n + j],
              "{} on {} boxes: missing ({}, {})", setup.label, n, i, j);
}

void checkRefused(const Setup& setup, const std::vector<Aabb>& boxes, std::size_t badBox) {
  const auto broadPhase = setup.make();
  std::vector<Pair> pairs;
  try {
    broadPhase->findPairs(boxes, pairs);
  } catch (const InputError& e) {
    require(e.object() == badBox, "{}: NaN in box {} reported as {}", setup.label, badBox, e.what());
    return;
  }
  require(false, "{}: NaN in box {} accepted", setup.label, badBox);
}

// The key map's contract on the scene's own values: float order is key order.
void checkKeyOrder(const std::vector<Aabb>& boxes) {
  std::vector<float> values;
  for (const Aabb& b : boxes)
    for (int a = 0; a < 3; ++a)
      for (float v : {b.min[a], b.max[a]})
        if (!std::isnan(v)) values.push_back(v);
  for (std::size_t t = 1; t < values.size(); ++t) {
    const float x = values[t - 1], y = values[t];
    const std::uint32_t kx = floatToKey(x), ky = floatToKey(y);
    require((x < y) == (kx < ky) && (x == y) == (kx == ky),
            "keys {:#x} {:#x} misorder {} {}", kx, ky, x, y);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  const std::uint8_t cellByte = in.byte();
  const std::optional<std::size_t> cell =
      cellByte == 0 ? std::nullopt : std::optional<std::size_t>(1 + (cellByte - 1) % 40);
  // The model device's key width, from the same byte's quotient: below 32 the
  // broad phase narrows each cell's keys and checks the pairs with the full ones.
  constexpr unsigned kKeyWidths[] = {32, 16, 4, 1};
  const unsigned keyWidth = cellByte == 0 ? 32 : kKeyWidths[((cellByte - 1) / 40) % 4];
  const std::uint8_t mByte = in.byte();
  const std::size_t m = 1 + mByte % 8;
  const std::size_t threads = mByte & 0x80 ? 2 : 1;
  const std::size_t cellsPerBatch = 1 + 3 * ((mByte >> 3) & 3u);
  const std::size_t batchCells = 1 + ((mByte >> 5) & 3u);
  const std::uint8_t capacityByte = in.byte();
  const std::size_t capacity = std::max<std::size_t>(2, m * (1 + (capacityByte & 0x7fu) % (24 / m + 1)));
  // The stream architecture's model (bipartite chunk pairs) or the seed's (triangular ones).
  const std::uint64_t streamReadLatency = capacityByte & 0x80u ? 4 : 0;
  const char* const arch = streamReadLatency ? "stream" : "seed";
  const std::vector<Aabb> boxes = decodeScene(in);

  CpuBackend cpu;
  DeviceParams params = streamReadLatency ? DeviceParams::stream(m, capacity, /*runOverheadCycles=*/3, streamReadLatency)
                                          : DeviceParams::seed(m, capacity, /*runOverheadCycles=*/3);
  params.batchCells = batchCells;
  params.keyWidth = keyWidth;
  ModelBackend model(params);
  std::vector<Setup> setups;
  std::vector<std::optional<std::size_t>> cells{std::nullopt};
  if (cell) cells.push_back(cell);
  for (const auto& c : cells) {
    const std::string cellName = c ? std::to_string(*c) : "none";
    setups.push_back({"cpu cell " + cellName,
                      [&cpu, c] { return std::make_unique<BroadPhase>(cpu, BroadPhaseConfig{.cellSize = c}); }});
    setups.push_back({fmt::format("model {} m {} capacity {} keys {} cell {} batch {}/{}", arch, m, capacity, keyWidth,
                                  cellName, cellsPerBatch, batchCells),
                      [&model, c, cellsPerBatch] {
                        return std::make_unique<BroadPhase>(model,
                                                            BroadPhaseConfig{.cellSize = c, .cellsPerBatch = cellsPerBatch});
                      }});
  }
  if (cell) {
    setups.push_back({"cpu grid cell " + std::to_string(*cell), [&cpu, cell] {
                        return std::make_unique<BroadPhase>(
                            cpu, BroadPhaseConfig{.cellSize = cell, .partition = PartitionKind::UniformGrid});
                      }});
    setups.push_back({fmt::format("model {} m {} capacity {} keys {} grid cell {} batch {}/{}", arch, m, capacity,
                                  keyWidth, *cell, cellsPerBatch, batchCells),
                      [&model, cell, cellsPerBatch] {
                        return std::make_unique<BroadPhase>(model, BroadPhaseConfig{.cellSize = cell,
                                                                                    .partition = PartitionKind::UniformGrid,
                                                                                    .cellsPerBatch = cellsPerBatch});
                      }});
  }
  if (threads > 1 && cell) {
    const auto makeModel = [params]() -> std::unique_ptr<Backend> { return std::make_unique<ModelBackend>(params); };
    setups.push_back({fmt::format("model {} m {} capacity {} keys {} cell {} threads {} batch {}/{}", arch, m, capacity,
                                  keyWidth, *cell, threads, cellsPerBatch, batchCells),
                      [makeModel, cell, threads, cellsPerBatch] {
                        return std::make_unique<BroadPhase>(
                            makeModel,
                            BroadPhaseConfig{.cellSize = cell, .threads = threads, .cellsPerBatch = cellsPerBatch});
                      }});
  }
  if (const auto bad = firstBoxWithNaN(boxes)) {
    for (const Setup& setup : setups) checkRefused(setup, boxes, *bad);
    return 0;
  }
  checkKeyOrder(boxes);
  const ExpectedPairs expected(boxes);
  for (const Setup& setup : setups) checkExact(setup, boxes, expected);
  return 0;
}
