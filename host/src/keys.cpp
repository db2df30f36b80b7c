#include "keys.hpp"

#include <bit>
#include <cmath>

#include <fmt/format.h>

namespace bpaccel {

InputError::InputError(std::size_t object, const std::string& reason)
    : std::runtime_error(fmt::format("object {}: {}", object, reason)), object_(object) {}

std::uint32_t floatToKey(float value) {
  // -0.0 + 0.0 is +0.0 (round to nearest): one key for both zeros.
  const auto bits = std::bit_cast<std::uint32_t>(value + 0.0f);
  // Negative floats order backwards in their bits: flip them all; positives
  // just move above every negative by setting the sign bit. Branch-free.
  const std::uint32_t flip = static_cast<std::uint32_t>(-static_cast<std::int32_t>(bits >> 31)) | 0x80000000u;
  return bits ^ flip;
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
    // min <= max is false when either is NaN, so one test per axis guards both cases.
    const bool valid = (b.min[0] <= b.max[0]) & (b.min[1] <= b.max[1]) & (b.min[2] <= b.max[2]);
    if (!valid) [[unlikely]] {
      for (int a = 0; a < 3; ++a) {
        if (std::isnan(b.min[a]) || std::isnan(b.max[a]))
          throw InputError(i, fmt::format("NaN coordinate on axis {}", kAxis[a]));
        if (b.min[a] > b.max[a])
          throw InputError(i, fmt::format("min {} > max {} on axis {}", b.min[a], b.max[a], kAxis[a]));
      }
    }
    for (int a = 0; a < 3; ++a) {
      out[i].min[a] = floatToKey(b.min[a]);
      out[i].max[a] = floatToKey(b.max[a]);
    }
  }
}

}  // namespace bpaccel
