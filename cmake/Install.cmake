# `cmake --install build --prefix P` (docs/architecture.md "Installing the libraries"):
# the libraries a simulator links (static), their headers, a CMake package
# (find_package(atonlab) -> atonlab::display, atonlab::stimuli, atonlab::protocols, atonlab::store,
# atonlab::analysis, atonlab::common, atonlab::present, atonlab::bench) and a
# pkg-config file (atonlab.pc), all relocatable; and the `atonlab` program.
# Components: "development" (libraries, headers, package files) and "runtime" (the
# program); tests/install/consumer.sh installs the first and builds against it.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(atonlab_installed_libraries display stimuli protocols store analysis common present bench)
set(atonlab_installed_targets)
foreach(lib IN LISTS atonlab_installed_libraries)
  set_target_properties(atonlab_${lib} PROPERTIES EXPORT_NAME ${lib})
  list(APPEND atonlab_installed_targets atonlab_${lib})
endforeach()
# The compile policy: static libraries name it (LINK_ONLY) in their link
# interface, so it travels with them; it carries no flags a consumer sees.
set_target_properties(atonlab_policy PROPERTIES EXPORT_NAME policy)
set_target_properties(atonlab_warnings PROPERTIES EXPORT_NAME warnings)
set_target_properties(atonlab_sanitize PROPERTIES EXPORT_NAME sanitize)

install(TARGETS ${atonlab_installed_targets} atonlab_policy atonlab_warnings atonlab_sanitize
        EXPORT atonlabTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(lib IN LISTS atonlab_installed_libraries)  # each library's headers: <lib>/include/atonlab/<lib>/
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${lib}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          COMPONENT development)
endforeach()
install(TARGETS atonlab RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)

set(atonlab_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/atonlab)
install(EXPORT atonlabTargets NAMESPACE atonlab:: DESTINATION ${atonlab_cmake_dir} COMPONENT development)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/atonlabConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/atonlabConfig.cmake INSTALL_DESTINATION ${atonlab_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/atonlabConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/atonlabConfig.cmake ${PROJECT_BINARY_DIR}/atonlabConfigVersion.cmake
        DESTINATION ${atonlab_cmake_dir} COMPONENT development)

# pkg-config: one file for all the libraries (they are static, so their
# dependencies are Requires, not Requires.private). prefix from ${pcfiledir}:
# the file stays right wherever the prefix is moved.
file(RELATIVE_PATH atonlab_pc_to_prefix /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" atonlab_pc_to_prefix "${atonlab_pc_to_prefix}")
# Libraries built with the sanitizers (ATONLAB_SANITIZE) call into their
# runtimes: a consumer must link them too, so the .pc file says so.
set(atonlab_pc_sanitize_libs "")
if(ATONLAB_SANITIZE)
  set(atonlab_pc_sanitize_libs " -fsanitize=address,undefined")
endif()
configure_file(${PROJECT_SOURCE_DIR}/cmake/atonlab.pc.in ${PROJECT_BINARY_DIR}/atonlab.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/atonlab.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT development)
