// readBoxes on any bytes: either boxes that obey the format's rules, or a
// ParseError naming the first bad line of the input. Anything else (a crash, a sanitizer
// report, a hang, another exception type) is a bug. What it accepts must also
// read back bit for bit after printing with the shortest round-trip form.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "core/box_file.hpp"
#include "fuzz_check.hpp"

using namespace bpaccel;
using bpaccel::fuzz::require;

namespace {

// Lines as std::getline sees them: a last line without '\n' still counts.
std::size_t lineCount(std::string_view text) {
  const auto newlines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
  return newlines + (!text.empty() && text.back() != '\n');
}

std::vector<Aabb> parse(const std::string& text) {
  std::istringstream in(text);
  return readBoxes(in);
}

void checkBoxes(const std::vector<Aabb>& boxes, std::size_t lines) {
  require(boxes.size() <= lines, "{} boxes from {} lines", boxes.size(), lines);
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      const float lo = boxes[i].min[a], hi = boxes[i].max[a];
      require(!std::isnan(lo) && !std::isnan(hi), "box {} axis {} holds NaN", i, a);
      require(lo <= hi, "box {} axis {}: min {} > max {}", i, a, lo, hi);
    }
}

// fmt's "{}" prints a float in the shortest form that reads back exactly
// ("-0", "inf", "1e-45"), so accepted boxes must survive a round trip.
void checkRoundTrip(const std::vector<Aabb>& boxes) {
  std::string text;
  for (const Aabb& b : boxes)
    fmt::format_to(std::back_inserter(text), "{} {} {} {} {} {}\n", b.min[0], b.min[1], b.min[2], b.max[0], b.max[1],
                   b.max[2]);
  std::vector<Aabb> again;
  try {
    again = parse(text);
  } catch (const ParseError& e) {
    require(false, "printed boxes do not read back: {}", e.what());
  }
  require(again.size() == boxes.size(), "round trip changed the box count");
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a)
      require(std::bit_cast<std::uint32_t>(again[i].min[a]) == std::bit_cast<std::uint32_t>(boxes[i].min[a]) &&
                  std::bit_cast<std::uint32_t>(again[i].max[a]) == std::bit_cast<std::uint32_t>(boxes[i].max[a]),
              "box {} axis {} changed in the round trip", i, a);
}

// The first `count` lines of `text`, each with its line end.
std::string firstLines(const std::string& text, std::size_t count) {
  std::size_t end = 0;
  for (std::size_t line = 0; line < count && end < text.size(); ++line) {
    const auto newline = text.find('\n', end);
    end = newline == std::string::npos ? text.size() : newline + 1;
  }
  return text.substr(0, end);
}

// The error names the line at fault: every line before it reads cleanly, and
// the text up to and including it fails with the same message.
void checkErrorLine(const std::string& text, std::size_t lines, const ParseError& error) {
  const std::size_t line = error.line();
  require(line >= 1 && line <= lines, "error on line {} of {}: {}", line, lines, error.what());
  require(std::string_view(error.what()).starts_with(fmt::format("line {}: ", line)),
          "message does not start with its line: {}", error.what());
  try {
    checkBoxes(parse(firstLines(text, line - 1)), line - 1);
  } catch (const ParseError& before) {
    require(false, "error reported on line {} but line {} is bad already", line, before.line());
  }
  try {
    parse(firstLines(text, line));
  } catch (const ParseError& same) {
    require(std::string_view(same.what()) == error.what(),
            "line {} alone fails differently: '{}' vs '{}'", line, same.what(), error.what());
    return;
  }
  require(false, "error reported on line {}, but the text up to it reads cleanly", line);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::size_t lines = lineCount(text);
  std::vector<Aabb> boxes;
  try {
    boxes = parse(text);
  } catch (const ParseError& e) {
    checkErrorLine(text, lines, e);
    return 0;
  }
  checkBoxes(boxes, lines);
  checkRoundTrip(boxes);
  return 0;
}
