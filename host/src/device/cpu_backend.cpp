#include "cpu_backend.hpp"

namespace bpaccel {

void CpuBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  const std::size_t before = out.size();
  kernel_.run(boxes, out, scratch_);
  stats.runs += 1;
  stats.batches += 1;
  stats.hits += out.size() - before;
}

}  // namespace bpaccel
