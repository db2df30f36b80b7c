#pragma once
// The median the host's figures report: of an even count, the mean of the two middle values.

#include <algorithm>
#include <vector>

namespace bpaccel {

/// The median of `values` (0 for none).
inline double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const std::size_t h = values.size() / 2;
  return values.size() % 2 ? values[h] : (values[h - 1] + values[h]) / 2;
}

}  // namespace bpaccel
