# Installs Cairn from BUILD_DIR into a scratch prefix, builds consumer/ against it with find_package(Cairn) and
# runs it. Fails on any step, if the sphere did not fall (10 m minus about 4.9 m), or if the navmesh tile over
# the floor has no polygon.
set(prefix "${WORK_DIR}/prefix")
set(consumer_build "${WORK_DIR}/consumer")
file(REMOVE_RECURSE "${WORK_DIR}")

execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" RESULT_VARIABLE result
                OUTPUT_QUIET)
if(NOT result EQUAL 0)
    message(FATAL_ERROR "cmake --install failed")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -S "${CMAKE_CURRENT_LIST_DIR}/consumer" -B "${consumer_build}"
                        -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
                RESULT_VARIABLE result OUTPUT_QUIET)
if(NOT result EQUAL 0)
    message(FATAL_ERROR "find_package(Cairn) project did not configure")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${consumer_build}" RESULT_VARIABLE result)
if(NOT result EQUAL 0)
    message(FATAL_ERROR "the consumer did not build against the installed cairn::physics and cairn::navmesh")
endif()
execute_process(COMMAND "${consumer_build}/consumer" OUTPUT_VARIABLE output RESULT_VARIABLE result)
if(NOT result EQUAL 0 OR NOT output MATCHES "height after 1 s: 5\\." OR NOT output MATCHES "navmesh tile polygons: [1-9]")
    message(FATAL_ERROR "the consumer ran wrong: '${output}'")
endif()
message(STATUS "installed package works: ${output}")
