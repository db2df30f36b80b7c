# Initial cache (cmake -C) for the host build `make test` runs its tests on:
# every target at -O1, as the tests' own files are. That build times nothing
# (the benchmark builds at -O3, in a folder of its own), and at -O1 the build
# takes 318 CPU-s where -O3 took 369.
set(CMAKE_BUILD_TYPE Check CACHE STRING "")
set(CMAKE_CXX_FLAGS_CHECK "-O1 -DNDEBUG" CACHE STRING "")
