// The binning device a program was built for: the generator's
// bpaccel_binning_params.h (EmitBinning --params-only; `make host` writes it).
#include "binning_params_of_header.hpp"

namespace bpaccel {

BinningParams builtBinningParams() { return binningParamsOfIncludedHeader(); }

}  // namespace bpaccel
