#pragma once
// Software alone: the all-pairs kernel as a device without a capacity.

#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "../core/all_pairs_kernel.hpp"
#include "backend.hpp"

namespace bpaccel {

/// Software alone: all pairs of the batch with SIMD compares (AllPairsKernel),
/// no capacity limit. One instance per thread: it keeps scratch space.
class CpuBackend final : public Backend {
 public:
  std::string name() const override { return "cpu"; }
  std::size_t capacity() const override { return std::numeric_limits<std::size_t>::max(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  std::string_view isa() const { return kernel_.isa(); }
  const AllPairsKernel* hostKernel() const override { return &kernel_; }

 private:
  AllPairsKernel kernel_;
  AllPairsKernel::Scratch scratch_;
};

}  // namespace bpaccel
