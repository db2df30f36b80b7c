# The hardware configuration the host is built for, as the generator wrote it
# beside the Verilog: bpaccel_params.h is the source the C++ reads; where the
# generator also wrote bpaccel_params.json, its values must agree with the header.
file(STRINGS "${BPACCEL_VERILOG_DIR}/bpaccel_params.h" _bpaccel_defines REGEX "^#define BPACCEL_[A-Z_]+ ")
foreach(_line IN LISTS _bpaccel_defines)
  if(_line MATCHES "^#define (BPACCEL_[A-Z_]+) \"?([^\"]*)\"?$")
    set(${CMAKE_MATCH_1} "${CMAKE_MATCH_2}")
  endif()
endforeach()
foreach(_name BPACCEL_ARCH BPACCEL_M BPACCEL_CAPACITY BPACCEL_KEY_WIDTH)
  if(NOT DEFINED ${_name})
    message(FATAL_ERROR "${BPACCEL_VERILOG_DIR}/bpaccel_params.h defines no ${_name}: emit it again")
  endif()
endforeach()

set(_bpaccel_json "${BPACCEL_VERILOG_DIR}/bpaccel_params.json")
if(EXISTS "${_bpaccel_json}")
  file(READ "${_bpaccel_json}" _json)
  # JSON key and the header's macro of the same value.
  foreach(_pair "arch;BPACCEL_ARCH" "m;BPACCEL_M" "capacity;BPACCEL_CAPACITY" "key_width;BPACCEL_KEY_WIDTH")
    list(GET _pair 0 _key)
    list(GET _pair 1 _macro)
    string(JSON _value ERROR_VARIABLE _missing GET "${_json}" ${_key})
    if(NOT _missing AND NOT "${_value}" STREQUAL "${${_macro}}")
      message(FATAL_ERROR "${_bpaccel_json} has ${_key} = ${_value} but bpaccel_params.h has ${_macro} = "
                          "${${_macro}}: emit the Verilog again")
    endif()
  endforeach()
endif()
message(STATUS "bpaccel: host for arch=${BPACCEL_ARCH}, m=${BPACCEL_M}, capacity=${BPACCEL_CAPACITY}, "
               "key width=${BPACCEL_KEY_WIDTH} (${BPACCEL_VERILOG_DIR})")
