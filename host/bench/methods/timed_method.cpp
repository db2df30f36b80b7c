#include "timed_method.hpp"

#include <fmt/format.h>

#include "scenes/exact_pairs.hpp"

namespace bpaccel {

std::string_view kindName(MethodKind kind) {
  switch (kind) {
    case MethodKind::Bullet: return "bullet";
    case MethodKind::Peer: return "peer";
    case MethodKind::Accelerator: return "accelerator";
    case MethodKind::Cpu: return "cpu";
  }
  return "?";
}

bool mustBeExact(MethodKind kind) { return kind == MethodKind::Accelerator || kind == MethodKind::Cpu; }

SkipRule allPairsSkipReason(double maxTestsPerFrame) {
  return [maxTestsPerFrame](const SceneStart& start) -> std::optional<std::string> {
    const std::size_t objects = start.boxes.size();
    const double tests = static_cast<double>(objects) * (static_cast<double>(objects) - 1) / 2;
    if (tests <= maxTestsPerFrame) return std::nullopt;
    return fmt::format("tests all pairs: {:.2g} tests a frame, above the limit of {:.2g} (--max-all-pairs-tests)",
                       tests, maxTestsPerFrame);
  };
}

SkipRule sweepSkipReason(double maxTests) {
  return [maxTests](const SceneStart& start) -> std::optional<std::string> {
    const auto tests = static_cast<double>(pairsOverlappingOnX(start.boxes));
    if (tests <= maxTests) return std::nullopt;
    return fmt::format("its sweep along x tests every pair that overlaps on x, {:.2g} on this scene, and cannot be "
                       "stopped midway: above the limit of {:.2g} (--max-sweep-tests)",
                       tests, maxTests);
  };
}

}  // namespace bpaccel
