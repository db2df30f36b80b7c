#include "keys.hpp"

#include <bit>
#include <cmath>

#include <fmt/format.h>

namespace bpaccel {

InputError::InputError(std::size_t object, const std::string& reason)
    : std::runtime_error(fmt::format("object {}: {}", object, reason)), object_(object) {}

std::uint32_t floatToKey(float value) {
  if (value == 0.0f) value = 0.0f;  // -0.0 == +0.0: one key for both
  const auto bits = std::bit_cast<std::uint32_t>(value);
  // Negative floats order backwards in their bits: flip them all; positives
  // just move above every negative by setting the sign bit.
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

void checkObjectCount(std::uint64_t count) {
  if (count > kMaxObjects)
    throw InputError(static_cast<std::size_t>(kMaxObjects),
                     fmt::format("too many objects: {} exceed the 32-bit index limit of {}", count, kMaxObjects));
}

void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out) {
  checkObjectCount(boxes.size());
  out.resize(boxes.size());
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Aabb& b = boxes[i];
    for (int a = 0; a < 3; ++a) {
      if (std::isnan(b.min[a]) || std::isnan(b.max[a]))
        throw InputError(i, fmt::format("NaN coordinate on axis {}", kAxis[a]));
      if (b.min[a] > b.max[a])
        throw InputError(i, fmt::format("min {} > max {} on axis {}", b.min[a], b.max[a], kAxis[a]));
      out[i].min[a] = floatToKey(b.min[a]);
      out[i].max[a] = floatToKey(b.max[a]);
    }
  }
}

}  // namespace bpaccel
