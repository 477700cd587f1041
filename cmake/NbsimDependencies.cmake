# Finds every third-party dependency once and exposes it as an imported target.
# All of them come from Debian 12's packages (scripts/setup installs the missing ones).
find_package(PkgConfig REQUIRED)

# SystemC ships no CMake package on Debian: use pkg-config. Debian built it as C++17, so every
# translation unit that includes SystemC must see SC_CPLUSPLUS=201703L, or linking fails on
# sc_api_version_2_3_4_cxx202002L (docs/architecture.md, "Platform facts").
pkg_check_modules(SYSTEMC REQUIRED IMPORTED_TARGET systemc>=2.3 tlm)
add_library(nbsim::systemc INTERFACE IMPORTED)
target_link_libraries(nbsim::systemc INTERFACE PkgConfig::SYSTEMC)
target_compile_definitions(nbsim::systemc INTERFACE SC_CPLUSPLUS=201703L)

find_package(glm REQUIRED)
find_package(fmt REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(benchmark REQUIRED)
find_package(zstd REQUIRED)
find_package(ZLIB REQUIRED)

find_package(OpenImageIO REQUIRED)
# Debian's exported target lists /usr/include/opencv4, which is not installed: drop it.
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_oiio_inc)
  list(FILTER _oiio_inc EXCLUDE REGEX "opencv")
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_inc}")
endif()

set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)

if(NBSIM_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()

find_package(Threads REQUIRED)
