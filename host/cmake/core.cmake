# bpaccel_core: the host logic that needs no hardware model. Included by the
# host build (host/CMakeLists.txt) and by the fuzz build (host/fuzz), so the
# source list lives in one place.
add_library(bpaccel_core STATIC
  ${CMAKE_CURRENT_LIST_DIR}/../src/keys.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/box_file.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/backend.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/async_backend.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/serial_stage.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/paced_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/all_pairs_kernel.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/partition.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/kd_tree.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/uniform_grid.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/broad_phase.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../src/timeline.cpp)
# A build-tree path: the installed package (bullet_drop_in.cmake) adds its own.
target_include_directories(bpaccel_core PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_LIST_DIR}/../src>)
find_package(TBB REQUIRED)
find_package(Threads REQUIRED)  # AsyncBackend's thread
target_link_libraries(bpaccel_core PUBLIC fmt::fmt TBB::tbb Threads::Threads)
target_compile_options(bpaccel_core PRIVATE -Wall -Wextra -Wpedantic)
