#include "shell_format.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

void ShellFormat::check() const {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("shell format: " + what); };
  if (wordsPerBeat != 2 && wordsPerBeat != 4 && wordsPerBeat != 8 && wordsPerBeat != 16)
    fail(fmt::format("{} words a beat (streams of 64, 128, 256 or 512 bits have 2, 4, 8 or 16)", wordsPerBeat));
  if (keyWidth < 1 || keyWidth > 32) fail(fmt::format("key width {} outside 1 .. 32", keyWidth));
  if (boxWords != (keyWidth <= 16 ? 3u : 6u))
    fail(fmt::format("{} words a box with {}-bit keys (3 up to 16 bits, else 6)", boxWords, keyWidth));
  if (indexWidth < 1 || indexWidth > 32) fail(fmt::format("index width {} outside 1 .. 32", indexWidth));
  if (indexWords != (indexWidth <= 16 ? 1u : 2u))
    fail(fmt::format("{} index words with {}-bit indices (1 up to 16 bits, else 2)", indexWords, indexWidth));
  if (lanes < 1) fail("no lanes");
  if (capacity < 1 || (indexWidth < 32 && capacity > (std::size_t{1} << indexWidth)))
    fail(fmt::format("capacity {} does not fit {}-bit indices", capacity, indexWidth));
}

}  // namespace bpaccel
