# The installable library (docs/bullet.md): bpaccel::core (keys, k-d tree,
# BroadPhase, cpu and model backends) and bpaccel::bpaccel (the Bullet broad
# phase, bpaccel::Broadphase), exported as a CMake package and a pkg-config
# file. The rtl backend stays in the build tree: it is one Verilated
# configuration, compiled with build-tree paths, and serves the project's own
# tests and benchmark. Included at the end of host/CMakeLists.txt.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
set(BPACCEL_VERSION 0.1.0)
set(_bpaccel_src ${CMAKE_CURRENT_LIST_DIR}/../src)

# Public headers: the ones a user of the broad phase or the backends reaches,
# and the configuration the model backend is built for (bpaccel_params.h).
target_sources(bpaccel_core PUBLIC FILE_SET HEADERS BASE_DIRS ${_bpaccel_src} ${BPACCEL_VERILOG_DIR} FILES
  ${_bpaccel_src}/types.hpp ${_bpaccel_src}/all_pairs_kernel.hpp ${_bpaccel_src}/backend.hpp ${_bpaccel_src}/async_backend.hpp ${_bpaccel_src}/keys.hpp ${_bpaccel_src}/kd_tree.hpp
  ${_bpaccel_src}/partition.hpp ${_bpaccel_src}/uniform_grid.hpp
  ${_bpaccel_src}/broad_phase.hpp ${_bpaccel_src}/timeline.hpp ${_bpaccel_src}/box_file.hpp ${BPACCEL_VERILOG_DIR}/bpaccel_params.h)
# Installed users include <bpaccel/...> (the file set adds include/bpaccel/).
target_include_directories(bpaccel_core INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
set_target_properties(bpaccel_core PROPERTIES EXPORT_NAME core)

add_library(bpaccel_bullet STATIC ${_bpaccel_src}/bullet_drop_in.cpp)
target_sources(bpaccel_bullet PUBLIC FILE_SET HEADERS BASE_DIRS ${_bpaccel_src} FILES ${_bpaccel_src}/bullet_drop_in.hpp)
target_link_libraries(bpaccel_bullet PUBLIC bpaccel_core PkgConfig::BULLET PRIVATE fmt::fmt)
target_compile_options(bpaccel_bullet PRIVATE -Wall -Wextra -Wpedantic)
set_target_properties(bpaccel_bullet PROPERTIES EXPORT_NAME bpaccel)
add_library(bpaccel::core ALIAS bpaccel_core)
add_library(bpaccel::bpaccel ALIAS bpaccel_bullet)

install(TARGETS bpaccel_core bpaccel_bullet EXPORT bpaccelTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bpaccel)
set(_bpaccel_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/bpaccel)
install(EXPORT bpaccelTargets NAMESPACE bpaccel:: DESTINATION ${_bpaccel_cmake_dir})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/bpaccelConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/bpaccelConfig.cmake INSTALL_DESTINATION ${_bpaccel_cmake_dir})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/bpaccelConfigVersion.cmake
  VERSION ${BPACCEL_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/bpaccelConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/bpaccelConfigVersion.cmake
  DESTINATION ${_bpaccel_cmake_dir})
# pkg-config: the prefix is found from the .pc file's own place, so a staged
# or moved install works.
file(RELATIVE_PATH BPACCEL_PC_TO_PREFIX "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
configure_file(${CMAKE_CURRENT_LIST_DIR}/bpaccel.pc.in ${CMAKE_CURRENT_BINARY_DIR}/bpaccel.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/bpaccel.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# Whole-step timing for the benchmark (bouncing cube with any broad phase).
target_sources(bpaccel_bench PRIVATE ${_bpaccel_src}/step_timing.cpp)
target_link_libraries(bpaccel_bench PUBLIC bpaccel_bullet)

target_sources(host_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR}/../tests/drop_in_test.cpp)
target_link_libraries(host_tests PRIVATE bpaccel_bullet)

# The example project outside the host tree, built against a staged install.
add_test(NAME installed_package_example
  COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${CMAKE_BINARY_DIR} -DSTAGE=${CMAKE_BINARY_DIR}/example-stage
          -DEXAMPLE_SOURCE=${CMAKE_CURRENT_LIST_DIR}/../examples/bullet_world
          -DGENERATOR=${CMAKE_GENERATOR} -DCXX=${CMAKE_CXX_COMPILER}
          -P ${CMAKE_CURRENT_LIST_DIR}/run_example.cmake)
set_tests_properties(installed_package_example PROPERTIES TIMEOUT 300)
