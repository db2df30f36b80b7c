#include "timed_method.hpp"

#include <fmt/format.h>

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

std::function<std::optional<std::string>(std::size_t)> allPairsSkipReason(double maxTestsPerFrame) {
  return [maxTestsPerFrame](std::size_t objects) -> std::optional<std::string> {
    const double tests = static_cast<double>(objects) * (static_cast<double>(objects) - 1) / 2;
    if (tests <= maxTestsPerFrame) return std::nullopt;
    return fmt::format("tests all pairs: {:.2g} tests a frame, above the limit of {:.2g} (--max-all-pairs-tests)",
                       tests, maxTestsPerFrame);
  };
}

}  // namespace bpaccel
