#pragma once
// What the CPU this runs on offers beyond the x86-64 baseline (SSE2): the one
// place the host asks, so every vector loop picks its path by the same rule.

namespace bpaccel {

/// Whether the AVX2 loops may run here (the x86-64 baseline's SSE2 ones always may).
inline bool cpuHasAvx2() {
#if defined(__x86_64__)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

}  // namespace bpaccel
