#pragma once
// The benchmark tests' accelerator: this build's Verilated device on the
// default clock and link.

#include <memory>

#include "bpaccel_params.h"
#include "device/rtl/rtl_backend.hpp"
#include "methods/accelerator_method.hpp"

namespace bpaccel {

inline std::shared_ptr<DeviceConfig> rtlDevice() {
  auto d = std::make_shared<DeviceConfig>();
  d->backend = "rtl";
  d->makeBackend = [] { return std::make_unique<RtlBackend>(); };
  d->link.bytesPerBeat = 4;
  d->hardware = {{"m", BPACCEL_M}, {"capacity", BPACCEL_CAPACITY}};
  return d;
}

}  // namespace bpaccel
