// GL program helpers of the capture renderer: compile a shader, link a program (optionally capturing
// gl_Position with transform feedback), insert #defines into embedded GLSL. Also the one place that
// includes GL's core prototypes, so every capture file sees the same declarations.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>

#include "model/nbuffer/covering.h"

namespace nbsim::capture {

// Compiles one shader stage; throws std::runtime_error with GL's log, naming `name`, on failure.
GLuint compile_shader(GLenum type, const std::string& source, const char* name);

// Links the shaders into a program and deletes them. capture_position: record gl_Position with
// transform feedback (interleaved, one vec4 a vertex); capture_point_size: and gl_PointSize after
// it (five floats a vertex, for GL_POINTS draws). Throws std::runtime_error with GL's log.
GLuint link_program(std::initializer_list<GLuint> shaders, const char* name, bool capture_position = false,
                    bool capture_point_size = false);

// A vertex array of indexed triangles: `xyz` three floats a vertex at attribute 0 (vao, vbo), and
// `indices` three a triangle bound as its element buffer (ebo); the caller deletes the three.
void make_triangle_vertex_array(std::span<const float> xyz, std::span<const std::uint32_t> indices, GLuint& vao, GLuint& vbo,
                                GLuint& ebo);

// `source` with `defines` inserted after its #version line.
std::string with_defines(const char* source, const std::string& defines);

// The GLSL covering library (shaders/common/covering.glsl: nb_cover, nb_cover_sprite) for `spec`,
// with its #defines, to insert with with_defines() into a shader that queries an N-buffer.
std::string covering_glsl(const CoveringSpec& spec);

}  // namespace nbsim::capture
