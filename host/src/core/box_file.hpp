#pragma once
// The text format of `bpaccel pairs --input`: one box a line.

#include <istream>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "types.hpp"

namespace bpaccel {

/// A malformed line: names the file line and the reason.
class ParseError : public std::runtime_error {
 public:
  ParseError(std::size_t line, const std::string& reason);
  std::size_t line() const { return line_; }

 private:
  std::size_t line_;
};

/// Empty for a box the broad phase takes; else its first fault, named as
/// the box readers name it: "minx is NaN", "minx 2 > maxx 1".
std::string boxFault(const Aabb& box);

/// Reads `minx miny minz maxx maxy maxz` lines; blank lines and `#` comments
/// are skipped. Numbers are rounded to float exactly as C's strtof rounds
/// them: values too small for a normal float become the nearest denormal or
/// a signed zero. Values beyond the float range (|x| rounding above
/// 3.4028235e38) are rejected rather than silently made infinite; `inf` and
/// `-inf` are written as such. Any malformed line (field count, not a number, NaN,
/// min > max) throws ParseError with its 1-based line number; nothing is
/// returned partially.
std::vector<Aabb> readBoxes(std::istream& in);

/// Writes `boxes` one a line in the format readBoxes reads, each number the
/// shortest text that reads back as the same float (-0 stays -0, infinities
/// are written inf and -inf), so a written file reads back bit for bit.
void writeBoxes(std::ostream& out, std::span<const Aabb> boxes);

}  // namespace bpaccel
