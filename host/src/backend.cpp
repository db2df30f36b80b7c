#include "backend.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

std::uint64_t scheduleIssueCycles(std::uint64_t n, std::uint64_t m) {
  if (n < 2) return 0;
  const std::uint64_t blocks = (n - 2) / m + 1;
  return blocks * (n - 1) - m * blocks * (blocks - 1) / 2;
}

ModelBackend::ModelBackend(std::size_t m, std::size_t capacity, std::uint64_t runOverheadCycles)
    : m_(m), capacity_(capacity), overhead_(runOverheadCycles) {
  if (m == 0 || capacity < 2 || capacity % m != 0)
    throw std::invalid_argument(fmt::format("model: invalid m = {} / capacity = {}", m, capacity));
}

void ModelBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  const std::size_t n = boxes.size();
  if (n > capacity_) throw std::length_error(fmt::format("model: {} boxes exceed the capacity {}", n, capacity_));
  const std::size_t before = out.size();
  // Block b, window start s: lane k tests (b*m + k, s + k) while s + k < n,
  // exactly as the hardware's sequencer issues it. A beat is one cycle with a hit.
  std::uint64_t beats = 0;
  for (std::size_t base = 0; n >= 2 && base + 2 <= n; base += m_) {
    for (std::size_t s = base + 1; s < n; ++s) {
      bool hit = false;
      const std::size_t lanes = std::min(m_, n - s);
      for (std::size_t k = 0; k < lanes; ++k) {
        if (overlaps(boxes[base + k], boxes[s + k])) {
          out.emplace_back(static_cast<std::uint32_t>(base + k), static_cast<std::uint32_t>(s + k));
          hit = true;
        }
      }
      beats += hit;
    }
  }
  const std::uint64_t issue = scheduleIssueCycles(n, m_);
  stats.runs += 1;
  stats.issueCycles += issue;
  stats.cycles += n < 2 ? 0 : issue + overhead_;
  stats.hits += out.size() - before;
  stats.boxesSent += n;
  stats.beatsReceived += beats;
}

void CpuBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  const std::size_t n = boxes.size();
  for (int c = 0; c < 6; ++c) soa_[c].resize(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      soa_[a][i] = boxes[i].min[a];
      soa_[3 + a][i] = boxes[i].max[a];
    }
  const std::uint32_t *minX = soa_[0].data(), *minY = soa_[1].data(), *minZ = soa_[2].data();
  const std::uint32_t *maxX = soa_[3].data(), *maxY = soa_[4].data(), *maxZ = soa_[5].data();
  const std::size_t before = out.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t ax0 = minX[i], ay0 = minY[i], az0 = minZ[i];
    const std::uint32_t ax1 = maxX[i], ay1 = maxY[i], az1 = maxZ[i];
    for (std::size_t j = i + 1; j < n; ++j) {
      // Non-short-circuit form so the compiler can evaluate all six at once.
      const bool hit = (ax0 <= maxX[j]) & (minX[j] <= ax1) & (ay0 <= maxY[j]) & (minY[j] <= ay1) &
                       (az0 <= maxZ[j]) & (minZ[j] <= az1);
      if (hit) out.emplace_back(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
    }
  }
  stats.runs += 1;
  stats.hits += out.size() - before;
}

}  // namespace bpaccel
