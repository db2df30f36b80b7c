# Initial cache (cmake -C) for the sanitizer build of the host: the library,
# the Verilated models' transports, the CLI and every test under
# AddressSanitizer and UndefinedBehaviorSanitizer (Verilator's own C++:
# below). Any report aborts (no recovery), so a finding fails its test.
# libstdc++'s assertions add bounds checks to operator[].
# -O1 keeps the build and the slow Verilated tests affordable; no NDEBUG.
# -g1 (line tables) is what a report's stack trace reads, at two thirds of
# -g's compile time.
set(CMAKE_BUILD_TYPE Sanitize CACHE STRING "")
set(CMAKE_CXX_FLAGS_SANITIZE
    "-O1 -g1 -fno-omit-frame-pointer -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -D_GLIBCXX_ASSERTIONS"
    CACHE STRING "")
set(CMAKE_EXE_LINKER_FLAGS_SANITIZE "-fsanitize=address,undefined,float-cast-overflow" CACHE STRING "")
# Verilator's generated model and runtime are not the project's code: built
# without the sanitizers (cmake/verilated_model.cmake), the Verilated tests run
# several times faster; the transport and driver around them stay checked.
set(BPACCEL_VERILATED_COMPILE_OPTIONS "-fno-sanitize=all" CACHE STRING "")
# The library and its program only: the benchmark, which no engine links,
# and its tests run unsanitized in make test.
set(BPACCEL_BENCH OFF CACHE BOOL "" FORCE)
