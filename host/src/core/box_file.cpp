#include "box_file.hpp"

#include <charconv>
#include <clocale>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "keys.hpp"

namespace bpaccel {

ParseError::ParseError(std::size_t line, const std::string& reason)
    : std::runtime_error(fmt::format("line {}: {}", line, reason)), line_(line) {}

namespace {

constexpr const char* kField[6] = {"minx", "miny", "minz", "maxx", "maxy", "maxz"};

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// The "C" locale, so strtof reads '.' as the decimal point whatever locale
/// the program that uses this library has set.
class CLocale {
 public:
  CLocale() : locale_(newlocale(LC_ALL_MASK, "C", locale_t{})) {
    if (!locale_) throw std::runtime_error("cannot create the C locale");
  }
  ~CLocale() { freelocale(locale_); }
  CLocale(const CLocale&) = delete;
  CLocale& operator=(const CLocale&) = delete;
  locale_t get() const { return locale_; }

 private:
  locale_t locale_;
};

/// A number from_chars found out of range, rounded exactly as strtof rounds
/// it: an underflow becomes the nearest denormal or a signed zero. Returns
/// false for an overflow, which becomes an infinity in strtof.
bool roundOutOfRange(std::string_view digits, float& value) {
  static_assert(std::numeric_limits<float>::has_denorm == std::denorm_present);
  const CLocale c;
  const std::string text(digits);
  char* end = nullptr;
  value = strtof_l(text.c_str(), &end, c.get());
  if (end != text.c_str() + text.size()) throw std::logic_error("strtof read less than from_chars");
  return !std::isinf(value);
}

}  // namespace

std::string boxFault(const Aabb& box) {
  for (int f = 0; f < 6; ++f)
    if (std::isnan(f < 3 ? box.min[f] : box.max[f - 3])) return fmt::format("{} is NaN", kField[f]);
  for (int a = 0; a < 3; ++a)
    if (box.min[a] > box.max[a]) return fmt::format("{} {} > {} {}", kField[a], box.min[a], kField[a + 3], box.max[a]);
  return {};
}

std::vector<Aabb> readBoxes(std::istream& in) {
  std::vector<Aabb> boxes;
  std::string text;
  std::size_t lineNo = 0;
  while (std::getline(in, text)) {
    ++lineNo;
    const auto hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    float v[6];
    int fields = 0;
    const char* p = text.data();
    const char* end = p + text.size();
    while (true) {
      while (p < end && isSpace(*p)) ++p;
      if (p == end) break;
      const char* tokenEnd = p;
      while (tokenEnd < end && !isSpace(*tokenEnd)) ++tokenEnd;
      const std::string_view token(p, static_cast<std::size_t>(tokenEnd - p));
      if (fields == 6) throw ParseError(lineNo, "more than 6 fields (expected minx miny minz maxx maxy maxz)");
      float value = 0;
      // from_chars takes no leading '+', which people write; allow one.
      const char* digits = (*p == '+' && tokenEnd - p > 1 && p[1] != '-' && p[1] != '+') ? p + 1 : p;
      const auto [ptr, ec] = std::from_chars(digits, tokenEnd, value);
      if ((ec != std::errc() && ec != std::errc::result_out_of_range) || ptr != tokenEnd)
        throw ParseError(lineNo, fmt::format("{} '{}' is not a number", kField[fields], token));
      // from_chars calls underflows out of range too; they are valid coordinates.
      if (ec == std::errc::result_out_of_range &&
          !roundOutOfRange(std::string_view(digits, static_cast<std::size_t>(tokenEnd - digits)), value))
        throw ParseError(lineNo, fmt::format("{} '{}' is beyond the float range (largest magnitude {}); write inf "
                                             "for an infinite coordinate",
                                             kField[fields], token, std::numeric_limits<float>::max()));
      if (std::isnan(value)) throw ParseError(lineNo, fmt::format("{} is NaN", kField[fields]));
      v[fields++] = value;
      p = tokenEnd;
    }
    if (fields == 0) continue;
    if (fields != 6)
      throw ParseError(lineNo, fmt::format("{} fields, expected 6 (minx miny minz maxx maxy maxz)", fields));
    const Aabb box{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    if (const std::string fault = boxFault(box); !fault.empty()) throw ParseError(lineNo, fault);
    if (boxes.size() == kMaxObjects) throw ParseError(lineNo, "too many boxes for 32-bit indices");
    boxes.push_back(box);
  }
  if (in.bad()) throw ParseError(lineNo, "read error");
  return boxes;
}

void writeBoxes(std::ostream& out, std::span<const Aabb> boxes) {
  std::string text;
  for (const Aabb& b : boxes) {
    // fmt writes a float as its shortest round-trip form ("inf", "-0", "1e-45").
    fmt::format_to(std::back_inserter(text), "{} {} {} {} {} {}\n", b.min[0], b.min[1], b.min[2], b.max[0], b.max[1],
                   b.max[2]);
    if (text.size() > (1u << 16)) {
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
      text.clear();
    }
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

}  // namespace bpaccel
