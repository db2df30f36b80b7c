#pragma once
// A deliberately broken backend for the tests that must catch one: the cpu
// backend, losing every pair of each run's first box.

#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "device/cpu_backend.hpp"

namespace bpaccel::testing {

class DroppingBackend final : public Backend {
 public:
  std::string name() const override { return "cpu-dropping"; }
  std::size_t capacity() const override { return inner_.capacity(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override {
    const std::size_t before = out.size();
    inner_.run(boxes, out, stats);
    out.erase(std::remove_if(out.begin() + static_cast<std::ptrdiff_t>(before), out.end(),
                             [](const Pair& p) { return p.first == 0; }),
              out.end());
  }

 private:
  CpuBackend inner_;
};

}  // namespace bpaccel::testing
