# Build speed: ccache when it is installed, and precompiled headers for the heavy third-party
# headers (docs/testing.md "Build and CI times" has the measurements).
#
# NBSIM_PCH (default ON): each big library and the nbsim executable precompile the headers most of
# their files include; every test executable reuses one precompiled header (GoogleTest, JSON, fmt
# and the standard library). OFF builds every file from its own includes, which is how a missing
# #include shows (scripts/fuzz builds that way).
option(NBSIM_PCH "Precompile the heavy third-party headers" ON)

# ccache, when present and no launcher was chosen: its sloppiness settings let it cache files
# compiled against a precompiled header (the header is rebuilt in the same second as its users);
# the base directory and CCACHE_NOHASHDIR let a second clone hit the first clone's entries, also
# in the builds with debug information (the sanitizer and fuzz builds), whose debug information
# then names the first clone's folder.
find_program(NBSIM_CCACHE ccache)
if(NBSIM_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(_launcher ${CMAKE_COMMAND} -E env CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
      CCACHE_BASEDIR=${PROJECT_SOURCE_DIR} CCACHE_NOHASHDIR=true ${NBSIM_CCACHE})
  set(CMAKE_CXX_COMPILER_LAUNCHER ${_launcher})
  set(CMAKE_C_COMPILER_LAUNCHER ${_launcher})
  message(STATUS "nbsim: compiling through ${NBSIM_CCACHE}")
endif()

# The standard headers nearly every nbsim file includes.
set(NBSIM_PCH_STD <algorithm> <array> <cmath> <cstdint> <cstring> <filesystem> <fstream> <functional>
    <map> <memory> <optional> <set> <sstream> <stdexcept> <string> <string_view> <unordered_map>
    <utility> <variant> <vector>)

# nbsim_precompile(<target> <header>...): the standard set plus these headers, when NBSIM_PCH is on.
function(nbsim_precompile target)
  if(NBSIM_PCH)
    target_precompile_headers(${target} PRIVATE ${NBSIM_PCH_STD} ${ARGN})
    target_compile_options(${target} PRIVATE -Winvalid-pch)
  endif()
endfunction()

# nbsim_reuse_precompiled(<target> <from>): compile <target> against <from>'s precompiled header
# (the same compiler flags; GCC ignores a header built with other flags, and -Winvalid-pch says so).
function(nbsim_reuse_precompiled target from)
  if(NBSIM_PCH)
    target_precompile_headers(${target} REUSE_FROM ${from})
    target_compile_options(${target} PRIVATE -Winvalid-pch)
  endif()
endfunction()
