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

# With "undefined", three of its checks are left out and one is added:
# - null and object-size where AddressSanitizer runs too, which reports the
#   same faults (a null dereference as a SEGV with its stack, an access past
#   an object as an overflow); alignment, since the binary readers never
#   view a byte buffer through a wider type (they cast to char types only
#   and assemble fields from bytes). These checks on every dereference were
#   three quarters of UBSan's compile time: 48 s against 31 s of CPU for the
#   largest unity source (25 s with AddressSanitizer alone, 16 s plain);
# - float-cast-overflow, not in GCC's "undefined" group: a time stamp or
#   count from a damaged log converted to an integer out of its range.
function(imusysid_set_sanitizers target)
  if(IMUSYSID_SANITIZERS)
    string(REPLACE ";" "," _list "${IMUSYSID_SANITIZERS}")
    set(_flags -fsanitize=${_list})
    if("undefined" IN_LIST IMUSYSID_SANITIZERS)
      list(APPEND _flags -fsanitize=float-cast-overflow -fno-sanitize=alignment)
      if("address" IN_LIST IMUSYSID_SANITIZERS)
        list(APPEND _flags -fno-sanitize=null,object-size)
      endif()
    endif()
    target_compile_options(${target} PRIVATE ${_flags} -fno-omit-frame-pointer -fno-sanitize-recover=all)
    target_link_options(${target} PRIVATE ${_flags})
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

# imusysid_precompile_third_party(TARGET): the standard and third-party headers
# most of the library's, the tool's and the bench's sources include, parsed
# once per target into a precompiled header instead of once per source (with
# clang a clean test-command build took about 110 s less CPU). Third-party
# and standard headers only: a project header here would rebuild every
# source when it changes. A source built with flags of its own sets
# SKIP_PRECOMPILE_HEADERS.
function(imusysid_precompile_third_party target)
  target_precompile_headers(${target} PRIVATE
    <algorithm> <cmath> <cstdint> <functional> <limits> <map> <memory>
    <optional> <sstream> <string> <string_view> <utility> <vector>
    [["Eigen/Core"]] [["Eigen/Dense"]] [["glog/logging.h"]]
    [["nlohmann/json.hpp"]])
  imusysid_set_pch_warnings(${target})
endfunction()
