# FindRecast: Debian's librecast-dev ships headers under recastnavigation/ and no CMake config.
# Defines Recast::Recast, Recast::Detour and Recast::DetourCrowd (imported, SYSTEM headers) and Recast_FOUND.

find_path(Recast_INCLUDE_DIR NAMES Recast.h PATH_SUFFIXES recastnavigation)
find_library(Recast_LIBRARY NAMES Recast)
find_library(Detour_LIBRARY NAMES Detour)
find_library(DetourCrowd_LIBRARY NAMES DetourCrowd)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Recast REQUIRED_VARS Recast_LIBRARY Detour_LIBRARY DetourCrowd_LIBRARY
                                                        Recast_INCLUDE_DIR)

if(Recast_FOUND)
    if(NOT TARGET Recast::Recast)
        add_library(Recast::Recast UNKNOWN IMPORTED)
        set_target_properties(Recast::Recast PROPERTIES IMPORTED_LOCATION "${Recast_LIBRARY}"
                                                        INTERFACE_INCLUDE_DIRECTORIES "${Recast_INCLUDE_DIR}")
    endif()
    if(NOT TARGET Recast::Detour)
        add_library(Recast::Detour UNKNOWN IMPORTED)
        set_target_properties(Recast::Detour PROPERTIES IMPORTED_LOCATION "${Detour_LIBRARY}"
                                                        INTERFACE_INCLUDE_DIRECTORIES "${Recast_INCLUDE_DIR}")
    endif()
    if(NOT TARGET Recast::DetourCrowd)
        add_library(Recast::DetourCrowd UNKNOWN IMPORTED)
        set_target_properties(Recast::DetourCrowd PROPERTIES IMPORTED_LOCATION "${DetourCrowd_LIBRARY}"
                                                             INTERFACE_INCLUDE_DIRECTORIES "${Recast_INCLUDE_DIR}"
                                                             INTERFACE_LINK_LIBRARIES Recast::Detour)
    endif()
endif()
mark_as_advanced(Recast_INCLUDE_DIR Recast_LIBRARY Detour_LIBRARY DetourCrowd_LIBRARY)
