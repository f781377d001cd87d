# install() rules and the package config, so that find_package(priormap) gives priormap::core etc.
include(CMakePackageConfigHelpers)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/priormap DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS priormap_core priormap_render priormap_dsl priormap_priorlets priormap_slam priormap_prf priormap_grid
        EXPORT priormapTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS priormap RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The prior library, for reading and as a starting point (the library has it compiled in).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/priors/ DESTINATION ${CMAKE_INSTALL_DATADIR}/priormap/priors
        FILES_MATCHING PATTERN "*.prior")

set(PRIORMAP_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/priormap)
install(EXPORT priormapTargets NAMESPACE priormap:: DESTINATION ${PRIORMAP_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/priormapConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/priormapConfig.cmake
                              INSTALL_DESTINATION ${PRIORMAP_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/priormapConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/priormapConfig.cmake
              ${PROJECT_BINARY_DIR}/priormapConfigVersion.cmake
        DESTINATION ${PRIORMAP_CMAKE_DIR})
