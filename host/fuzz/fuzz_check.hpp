#pragma once
// A failed property in a fuzz target: print why and abort, which libFuzzer
// reports as a crash and saves the input that caused it. The message is only
// formatted on failure: checks run once per pair of every input.

#include <cstdio>
#include <cstdlib>
#include <utility>

#include <fmt/format.h>

namespace bpaccel::fuzz {

template <typename... Args>
void require(bool holds, fmt::format_string<Args...> why, Args&&... args) {
  if (holds) [[likely]]
    return;
  std::fprintf(stderr, "property violated: %s\n", fmt::format(why, std::forward<Args>(args)...).c_str());
  std::abort();
}

}  // namespace bpaccel::fuzz
