#pragma once
// What a driver must know of a shell's streams (docs/protocol.md): how its
// packets are laid out, and what a command may hold.

#include <cstddef>
#include <cstdint>

namespace bpaccel {

/// The layout of one shell's packets and the limits of its device. The
/// driver takes its shell's (ShellIdentity, from the generated bpaccel_shell.h)
/// and checks it against the device's registers when it probes; the codecs
/// take any, so they can be tested on layouts other than the built one.
struct ShellFormat {
  unsigned wordsPerBeat = 8;    // k: TDATA bits / 32
  unsigned boxWords = 6;        // 3 (keys of 16 bits or fewer, two a word) or 6 (a word a key)
  unsigned indexWords = 1;      // of a record's indices: 1 ({j, i}) or 2 (i, j)
  unsigned lanes = 8;           // m: bit k of a CELLS record's mask is lane k
  unsigned indexWidth = 11;     // a record's indices count modulo 2^indexWidth
  unsigned keyWidth = 32;       // bits of a key; the bits above must be 0
  std::size_t capacity = 2048;  // most boxes of a cell (CELLS) or a frame (FRAME)
  bool bipartite = true;        // a cell may carry a split
  unsigned cellBits = 0;        // FRAME (binning): at most 2^cellBits grid cells an axis; 0: no FRAME

  unsigned maskWords() const { return (lanes + 31) / 32; }
  /// Words of a CELLS record: its indices, its cell, its mask.
  unsigned recordWords() const { return indexWords + 1 + maskWords(); }
  /// `words` rounded up to whole beats.
  std::size_t paddedWords(std::size_t words) const { return (words + wordsPerBeat - 1) / wordsPerBeat * wordsPerBeat; }
  /// Throws std::invalid_argument naming the first field no shell has.
  void check() const;
};

}  // namespace bpaccel
