# The installable library (docs/bullet.md): every target of host/src but the
# Verilated device, exported as the CMake package `bpaccel` (bpaccel::core,
# bpaccel::partition, bpaccel::query, bpaccel::device, bpaccel::broad_phase,
# bpaccel::bpaccel, the Bullet drop-in, and the component bpaccel::fcl) and as
# a pkg-config file (without the FCL manager). Headers go
# to include/bpaccel/<folder>/, with the generator's bpaccel_params.h (the
# configuration the model backend is built for) beside device/built_device.hpp,
# which reads it.
include(CMakePackageConfigHelpers)
set(BPACCEL_VERSION 0.1.0)

install(TARGETS bpaccel_core bpaccel_partition bpaccel_query bpaccel_device bpaccel_broad_phase bpaccel_bullet
  EXPORT bpaccelTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bpaccel
  FILE_SET params DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bpaccel/device)
install(TARGETS bpaccel_binning
  EXPORT bpaccelTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bpaccel
  FILE_SET binparams DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bpaccel/device/binning)
set(_bpaccel_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/bpaccel)
install(EXPORT bpaccelTargets NAMESPACE bpaccel:: DESTINATION ${_bpaccel_cmake_dir})
# The FCL manager, where it was built: the package's optional component `fcl`
# (find_package(bpaccel COMPONENTS fcl), target bpaccel::fcl).
if(TARGET bpaccel_fcl)
  install(TARGETS bpaccel_fcl EXPORT bpaccelFclTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bpaccel)
  install(EXPORT bpaccelFclTargets NAMESPACE bpaccel:: DESTINATION ${_bpaccel_cmake_dir})
endif()
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
