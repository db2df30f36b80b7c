# Options for the C++ that Verilator writes and its runtime, apart from the
# host's own code in the same targets: the sanitizer build (sanitize.cmake)
# sets -fno-sanitize=all here, so its Verilated tests simulate at an
# unsanitized model's speed while every line the project wrote stays checked.
set(BPACCEL_VERILATED_COMPILE_OPTIONS "" CACHE STRING "Compile options for Verilator's generated model and runtime")

# Applies BPACCEL_VERILATED_COMPILE_OPTIONS to the sources verilate() gave `target`.
function(bpaccel_verilated_options target)
  if(NOT BPACCEL_VERILATED_COMPILE_OPTIONS)
    return()
  endif()
  get_target_property(sources ${target} SOURCES)
  foreach(source IN LISTS sources)
    if(source MATCHES "/V[A-Za-z0-9_]+\\.dir/|/include/verilated[a-z_]*\\.cpp$")
      set_property(SOURCE ${source} APPEND PROPERTY COMPILE_OPTIONS ${BPACCEL_VERILATED_COMPILE_OPTIONS})
      list(APPEND matched ${source})
    endif()
  endforeach()
  if(NOT matched)
    message(FATAL_ERROR "bpaccel_verilated_options(${target}): no Verilated source found among ${sources}")
  endif()
endfunction()
