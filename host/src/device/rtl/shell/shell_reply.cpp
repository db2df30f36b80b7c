#include "shell_reply.hpp"

#include <array>
#include <utility>

#include <fmt/format.h>

#include "bpaccel_shell.h"

namespace bpaccel {
namespace {

// The generated header's codes with their names, so that no code is spelled here.
#define BPACCEL_SHELL_ERROR_ENTRY(name) std::pair<std::uint32_t, const char*>{BPACCEL_SHELL_ERR_##name, #name}
constexpr std::array kErrorNames = {
    BPACCEL_SHELL_ERROR_ENTRY(NONE),           BPACCEL_SHELL_ERROR_ENTRY(COUNT_OVER_CAPACITY),
    BPACCEL_SHELL_ERROR_ENTRY(COUNT_OVER_LOADED), BPACCEL_SHELL_ERROR_ENTRY(LOAD_OVERFLOW),
    BPACCEL_SHELL_ERROR_ENTRY(SPLIT_OUT_OF_RANGE), BPACCEL_SHELL_ERROR_ENTRY(SPLIT_UNSUPPORTED),
    BPACCEL_SHELL_ERROR_ENTRY(BAD_COMMAND),    BPACCEL_SHELL_ERROR_ENTRY(LENGTH_MISMATCH),
    BPACCEL_SHELL_ERROR_ENTRY(KEY_TOO_WIDE),   BPACCEL_SHELL_ERROR_ENTRY(ABORTED),
    BPACCEL_SHELL_ERROR_ENTRY(KEY_OUT_OF_GRID), BPACCEL_SHELL_ERROR_ENTRY(BOX_SPANS_CELLS),
    BPACCEL_SHELL_ERROR_ENTRY(GROUP_OVERFLOW), BPACCEL_SHELL_ERROR_ENTRY(BAD_GRID),
    BPACCEL_SHELL_ERROR_ENTRY(BOX_INVERTED),
};
#undef BPACCEL_SHELL_ERROR_ENTRY

std::uint64_t word64(std::span<const std::uint32_t> t, unsigned at) {
  return t[at] | static_cast<std::uint64_t>(t[at + 1]) << 32;
}

}  // namespace

std::string shellErrorName(std::uint32_t code) {
  for (const auto& [c, name] : kErrorNames)
    if (c == code) return name;
  return fmt::format("error {}", code);
}

ShellDeviceError::ShellDeviceError(const std::string& command, const Trailer& trailer)
    : ShellError(fmt::format("shell: the device answered {} with {} (error code {}, detail {}); its records "
                             "were discarded",
                             command, shellErrorName(trailer.error), trailer.error, trailer.detail)),
      trailer_(trailer) {}

Trailer decodeTrailer(const ShellFormat& format, std::span<const std::uint32_t> reply) {
  constexpr std::size_t words = BPACCEL_SHELL_TRAILER_WORDS;
  if (reply.size() % format.wordsPerBeat != 0)
    throw ShellProtocolError(fmt::format("shell: a reply of {} words is not whole beats of {} words", reply.size(),
                                         format.wordsPerBeat));
  if (reply.size() < words)
    throw ShellProtocolError(fmt::format("shell: a reply of {} words is shorter than a trailer ({} words)",
                                         reply.size(), words));
  const auto t = reply.subspan(reply.size() - words);
  const std::uint32_t header = t[BPACCEL_SHELL_TRAILER_HEADER];
  if (header >> 24 != BPACCEL_SHELL_TRAILER_MAGIC)
    throw ShellProtocolError(fmt::format("shell: the reply's trailer has header {:#010x}, without the magic {:#x}",
                                         header, BPACCEL_SHELL_TRAILER_MAGIC));
  Trailer r;
  r.opcode = header >> 16 & 0xFFu;
  r.error = header >> 8 & 0xFFu;
  r.detail = t[BPACCEL_SHELL_TRAILER_DETAIL];
  r.records = t[BPACCEL_SHELL_TRAILER_RECORDS];
  r.boxes = t[BPACCEL_SHELL_TRAILER_BOXES];
  r.cells = t[BPACCEL_SHELL_TRAILER_CELLS];
  r.deviceCycles = word64(t, BPACCEL_SHELL_TRAILER_DEVICE_CYCLES);
  r.stallCycles = word64(t, BPACCEL_SHELL_TRAILER_STALL_CYCLES);
  r.issueCycles = word64(t, BPACCEL_SHELL_TRAILER_ISSUE_CYCLES);
  r.pairs = word64(t, BPACCEL_SHELL_TRAILER_PAIRS);
  r.intakeCycles = word64(t, BPACCEL_SHELL_TRAILER_INTAKE_CYCLES);
  if (r.intakeCycles > r.deviceCycles)
    throw ShellProtocolError(fmt::format("shell: the trailer counts {} intake cycles of {} device cycles",
                                         r.intakeCycles, r.deviceCycles));
  return r;
}

std::span<const std::uint32_t> recordWordsOf(const ShellFormat& format, std::span<const std::uint32_t> reply,
                                             const Trailer& trailer, unsigned recordWords) {
  const std::size_t used = std::size_t{trailer.records} * recordWords;
  const std::size_t body = reply.size() - BPACCEL_SHELL_TRAILER_WORDS;
  if (body != format.paddedWords(used))
    throw ShellProtocolError(fmt::format("shell: {} words before the trailer, but {} records of {} words fill {}",
                                         body, trailer.records, recordWords, format.paddedWords(used)));
  return reply.first(used);
}

}  // namespace bpaccel
