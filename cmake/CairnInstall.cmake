# `cmake --install` exports cairn::jobs, cairn::physics, cairn::navmesh and cairn::navmesh_io so that another project can
# find_package(Cairn). The navmesh's Recast/Detour are found by the FindRecast module installed next to the
# package config (Debian's librecast-dev has no CMake config of its own).

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS cairn_jobs cairn_physics cairn_navmesh cairn_navmesh_io EXPORT CairnTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# A module's include/ may not exist yet in a checkout (git keeps no empty folders): install those that do
foreach(module jobs physics navmesh)
    if(EXISTS "${PROJECT_SOURCE_DIR}/${module}/include")
        install(DIRECTORY ${module}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    endif()
endforeach()
install(EXPORT CairnTargets NAMESPACE cairn:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Cairn)

configure_package_config_file(cmake/CairnConfig.cmake.in "${CMAKE_CURRENT_BINARY_DIR}/CairnConfig.cmake"
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Cairn)
write_basic_package_version_file("${CMAKE_CURRENT_BINARY_DIR}/CairnConfigVersion.cmake"
                                 COMPATIBILITY SameMinorVersion)
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/CairnConfig.cmake" "${CMAKE_CURRENT_BINARY_DIR}/CairnConfigVersion.cmake"
              cmake/FindRecast.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Cairn)
