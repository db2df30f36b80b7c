#pragma once
// Float-to-key conversion and input validation.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "types.hpp"

namespace bpaccel {

class ThreadPool;

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

/// Checks every box: no NaN, min <= max on every axis (in key order, so -0.0
/// equals +0.0, and on the bits, so -ffast-math cannot fold it away), count
/// within kMaxObjects. Throws InputError for the first bad box, naming it, its
/// axis and its values; boxes[i] is named object firstIndex + i (the boxes
/// are then the part of a scene from there on).
void checkBoxes(std::span<const Aabb> boxes, std::size_t firstIndex = 0);

/// Checks every box as checkBoxes does and converts it to keys. Throws
/// InputError for the first bad box; `out` is reused across calls to avoid
/// allocation.
void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out);
/// The same, and the scene's bounds found in the same pass (a partition that
/// needs them then skips a pass of its own over the keys).
void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out, KeyBounds& bounds);

/// The same on the pool's threads, each converting a contiguous part (the
/// first bad box is still the one named).
void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out, KeyBounds& bounds, ThreadPool& pool);

/// The bounds of boxes already converted.
KeyBounds boundsOf(std::span<const KeyBox> boxes);

/// Conservative narrowing of one device cell's keys to `width` bits (1 .. 32),
/// for a device that compares narrower keys (BPACCEL_KEY_WIDTH < 32): on each
/// axis, a key becomes its distance from the cell's lowest min, shifted right
/// by the fewest bits that make the cell's range (up to its highest max) fit. That map is monotone
/// and mins and maxes share it, so a min <= max compare holds after it
/// wherever it held before: boxes that overlap still do. The device then
/// reports a superset of the cell's pairs, which the host cuts back with the
/// full keys (BroadPhase). A cell whose range fits in `width` bits narrows
/// exactly. Writes out[i] for box i of `cell` (the same size).
void narrowKeys(std::span<const KeyBox> cell, unsigned width, std::span<KeyBox> out);

namespace detail {
/// narrowKeys without its checks and without AVX2 (what CPUs without it run:
/// the map box by box, the bounds by boundsOf; the tests compare the two).
void narrowKeysScalar(std::span<const KeyBox> cell, unsigned width, std::span<KeyBox> out);
}  // namespace detail

/// Throws InputError when `count` objects cannot be indexed.
void checkObjectCount(std::uint64_t count);

}  // namespace bpaccel
