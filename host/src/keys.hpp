#pragma once
// Float-to-key conversion and input validation.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "types.hpp"

namespace bpaccel {

/// Bad input, naming the object (index) and the reason.
class InputError : public std::runtime_error {
 public:
  InputError(std::size_t object, const std::string& reason);
  std::size_t object() const { return object_; }

 private:
  std::size_t object_;
};

/// Order-preserving map float32 -> uint32: a < b as floats iff key(a) < key(b)
/// as integers, -0.0 and +0.0 map to the same key, +-infinity are the extreme
/// keys. NaN has no place in that order; callers reject it first.
std::uint32_t floatToKey(float value);

/// Largest number of objects one scene may hold: indices are 32-bit.
constexpr std::uint64_t kMaxObjects = 0xFFFFFFFFull;

/// Checks every box (no NaN, min <= max on every axis, count within kMaxObjects)
/// and converts it to keys. Throws InputError for the first bad box; `out` is
/// reused across calls to avoid allocation.
void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out);
/// The same, and the scene's bounds found in the same pass (a partition that
/// needs them then skips a pass of its own over the keys).
void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out, KeyBounds& bounds);

/// The bounds of boxes already converted.
KeyBounds boundsOf(std::span<const KeyBox> boxes);

/// Throws InputError when `count` objects cannot be indexed.
void checkObjectCount(std::uint64_t count);

}  // namespace bpaccel
