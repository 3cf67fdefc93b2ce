# Warning and sanitizer settings, applied per target (never globally) so they
# do not leak into projects that consume imusysid.

function(imusysid_set_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE
      -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Woverloaded-virtual)
    if(IMUSYSID_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
endfunction()

set(_imusysid_known_sanitizers address undefined thread leak)
foreach(s IN LISTS IMUSYSID_SANITIZERS)
  if(NOT s IN_LIST _imusysid_known_sanitizers)
    message(FATAL_ERROR "IMUSYSID_SANITIZERS: unknown sanitizer '${s}' (known: ${_imusysid_known_sanitizers})")
  endif()
endforeach()
if("thread" IN_LIST IMUSYSID_SANITIZERS AND "address" IN_LIST IMUSYSID_SANITIZERS)
  message(FATAL_ERROR "IMUSYSID_SANITIZERS: 'thread' and 'address' cannot be combined")
endif()

function(imusysid_set_sanitizers target)
  if(IMUSYSID_SANITIZERS)
    string(REPLACE ";" "," _list "${IMUSYSID_SANITIZERS}")
    target_compile_options(${target} PRIVATE -fsanitize=${_list} -fno-omit-frame-pointer -fno-sanitize-recover=all)
    target_link_options(${target} PRIVATE -fsanitize=${_list})
  endif()
endfunction()

# For a target that uses a precompiled header: CMake adds -Winvalid-pch, which
# says when GCC or Clang cannot use the header (different flags) and parses
# everything again. Reported, not an error: the build is still correct, only
# slower.
function(imusysid_set_pch_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wno-error=invalid-pch)
  endif()
endfunction()
