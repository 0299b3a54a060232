# Warnings and sanitizers shared by every Cairn target.

add_library(cairn_compile_options INTERFACE)
target_compile_options(cairn_compile_options INTERFACE -Wall -Wextra -Werror)

if(CAIRN_SANITIZER STREQUAL "address")
    target_compile_options(cairn_compile_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                           -fno-sanitize-recover=undefined)
    target_link_options(cairn_compile_options INTERFACE -fsanitize=address,undefined)
elseif(CAIRN_SANITIZER STREQUAL "thread")
    target_compile_options(cairn_compile_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
    target_link_options(cairn_compile_options INTERFACE -fsanitize=thread)
elseif(NOT CAIRN_SANITIZER STREQUAL "")
    message(FATAL_ERROR "CAIRN_SANITIZER must be '', 'address' or 'thread', not '${CAIRN_SANITIZER}'")
endif()

# Applies the shared options to a target without exporting them to Cairn's users.
function(cairn_target_defaults target)
    target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:cairn_compile_options>)
endfunction()
