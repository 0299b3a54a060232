# Warnings and sanitizers shared by every Cairn target.

add_library(cairn_compile_options INTERFACE)
target_compile_options(cairn_compile_options INTERFACE -Wall -Wextra -Werror)
if(CMAKE_UNITY_BUILD AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # A unity build (tools/run-tests.sh) includes each source into a batch file, where GCC takes a class that
    # holds a type of its source's anonymous namespace for a header's class that every includer would see
    # differently: correct code, warned of only because of the batching
    target_compile_options(cairn_compile_options INTERFACE -Wno-subobject-linkage)
endif()

if(CAIRN_SANITIZER STREQUAL "address")
    target_compile_options(cairn_compile_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                           -fno-sanitize-recover=undefined)
    target_link_options(cairn_compile_options INTERFACE -fsanitize=address,undefined)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
        # GCC 12 reports maybe-uninitialized inside <regex> once ASan instruments it (GCC bug 105562): a false
        # positive in the standard library that -Werror turned into a build that did not build
        target_compile_options(cairn_compile_options INTERFACE -Wno-maybe-uninitialized)
    endif()
elseif(CAIRN_SANITIZER STREQUAL "thread")
    target_compile_options(cairn_compile_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
    target_link_options(cairn_compile_options INTERFACE -fsanitize=thread)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
        # As under ASan: GCC 12 with TSan's instrumentation reports maybe-uninitialized on the move of a
        # disengaged std::optional (TileJob's result, inlined in a unity batch; GCC bug 80635). The Release
        # build keeps the warning
        target_compile_options(cairn_compile_options INTERFACE -Wno-maybe-uninitialized)
    endif()
elseif(NOT CAIRN_SANITIZER STREQUAL "")
    message(FATAL_ERROR "CAIRN_SANITIZER must be '', 'address' or 'thread', not '${CAIRN_SANITIZER}'")
endif()

if(CAIRN_BUILD_FUZZERS)
    if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang" OR NOT CAIRN_SANITIZER STREQUAL "address")
        message(FATAL_ERROR "CAIRN_BUILD_FUZZERS needs Clang (libFuzzer) and CAIRN_SANITIZER=address")
    endif()
    # The coverage for libFuzzer goes only to the readers the harnesses drive (tests/fuzz/CMakeLists.txt): its
    # hooks on every comparison made the physics tests in this build several times slower for no fuzzing gain
endif()

# Applies the shared options to a target without exporting them to Cairn's users.
function(cairn_target_defaults target)
    target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:cairn_compile_options>)
endfunction()
