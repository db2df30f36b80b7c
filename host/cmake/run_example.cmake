# ctest driver: install the host library into a staging prefix, then build
# and run host/examples/bullet_world against it twice: through
# find_package(bpaccel CONFIG) and through pkg-config; where the FCL manager
# was installed, host/examples/fcl_scene through find_package(bpaccel
# COMPONENTS fcl) too.
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}")
  endif()
endfunction()

file(REMOVE_RECURSE ${STAGE})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${STAGE})
set(example_build ${BUILD_DIR}/example-build)
file(REMOVE_RECURSE ${example_build})
run(${CMAKE_COMMAND} -S ${EXAMPLE_SOURCE} -B ${example_build} -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX}
    -DCMAKE_PREFIX_PATH=${STAGE} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${example_build})
run(${example_build}/bullet_world)

file(GLOB fcl_targets ${STAGE}/lib*/cmake/bpaccel/bpaccelFclTargets.cmake ${STAGE}/lib/*/cmake/bpaccel/bpaccelFclTargets.cmake)
if(fcl_targets)
  set(fcl_build ${BUILD_DIR}/example-fcl-build)
  file(REMOVE_RECURSE ${fcl_build})
  run(${CMAKE_COMMAND} -S ${FCL_EXAMPLE_SOURCE} -B ${fcl_build} -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX}
      -DCMAKE_PREFIX_PATH=${STAGE} -DCMAKE_BUILD_TYPE=Release)
  run(${CMAKE_COMMAND} --build ${fcl_build})
  run(${fcl_build}/fcl_scene)
endif()

# The same program from the pkg-config file alone.
file(GLOB pc_file ${STAGE}/lib*/pkgconfig/bpaccel.pc ${STAGE}/lib/*/pkgconfig/bpaccel.pc)
if(NOT pc_file)
  message(FATAL_ERROR "no bpaccel.pc under ${STAGE}")
endif()
get_filename_component(pc_dir ${pc_file} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
execute_process(COMMAND pkg-config --cflags --libs bpaccel OUTPUT_VARIABLE flags RESULT_VARIABLE rc
                OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config --cflags --libs bpaccel failed")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
run(${CXX} -std=c++20 -O1 ${EXAMPLE_SOURCE}/main.cpp -o ${example_build}/bullet_world_pkgconfig ${flags})
run(${example_build}/bullet_world_pkgconfig)
