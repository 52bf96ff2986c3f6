# `cmake --install BUILD --prefix P`: the hprt command (bin/), libhprt.so and
# its image codec module (lib/, lib/hprt/), the public headers
# (include/hprt/), the CMake package (lib/cmake/hprt/: hprt::hprt,
# hprt::plugin) and a pkg-config file (lib/pkgconfig/hprt.pc).
include(CMakePackageConfigHelpers)

install(TARGETS hprt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS hprt_oiio LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/hprt)
install(TARGETS hprt_api hprt_plugin_abi EXPORT hprtTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_SOURCE_DIR}/include/hprt/hprt.h ${PROJECT_SOURCE_DIR}/include/hprt/plugin.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/hprt)

set(_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/hprt)
install(EXPORT hprtTargets NAMESPACE hprt:: DESTINATION ${_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/hprtConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/hprtConfig.cmake INSTALL_DESTINATION ${_cmake_dir})
# 0.x: a new minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/hprtConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/hprtConfig.cmake ${PROJECT_BINARY_DIR}/hprtConfigVersion.cmake
        DESTINATION ${_cmake_dir})

# Relocatable: the prefix is found from the .pc file's own place.
file(RELATIVE_PATH _pc_up "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
string(REGEX REPLACE "/$" "" _pc_up "${_pc_up}")
set(HPRT_PC_PREFIX "\${pcfiledir}/${_pc_up}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/hprt.pc.in ${PROJECT_BINARY_DIR}/hprt.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/hprt.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
