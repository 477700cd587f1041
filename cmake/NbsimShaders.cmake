# nbsim_embed_shaders(<target> <files...>): compiles the GLSL files of shaders/ into the target as
# strings named after their path below shaders/ (nbsim::shaders::<folder>_<name>, e.g.
# shaders/common/scene.vert -> common_scene_vert, shaders/particles/particles.vert ->
# particles_particles_vert), so the binary runs from anywhere and two techniques' folders may
# hold files of the same name. Editing a shader re-runs the configure step.
function(nbsim_embed_shaders target)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/nbsim_shaders.cpp)
  set(hdr ${CMAKE_CURRENT_BINARY_DIR}/nbsim_shaders.h)
  set(body "// Generated from shaders/ by cmake/NbsimShaders.cmake. Do not edit.\n#include \"nbsim_shaders.h\"\nnamespace nbsim::shaders {\n")
  set(decl "// Generated from shaders/ by cmake/NbsimShaders.cmake. Do not edit.\n#pragma once\nnamespace nbsim::shaders {\n")
  foreach(f ${ARGN})
    file(RELATIVE_PATH name ${PROJECT_SOURCE_DIR}/shaders ${f})
    string(REGEX REPLACE "[./]" "_" sym ${name})
    file(READ ${f} text)
    string(APPEND body "extern const char* const ${sym} = R\"nbsim_glsl(${text})nbsim_glsl\";\n")
    string(APPEND decl "extern const char* const ${sym};\n")
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${f})
  endforeach()
  string(APPEND body "}  // namespace nbsim::shaders\n")
  string(APPEND decl "}  // namespace nbsim::shaders\n")
  file(CONFIGURE OUTPUT ${out} CONTENT "${body}" @ONLY)
  file(CONFIGURE OUTPUT ${hdr} CONTENT "${decl}" @ONLY)
  target_sources(${target} PRIVATE ${out})
  target_include_directories(${target} PUBLIC ${CMAKE_CURRENT_BINARY_DIR})
endfunction()
