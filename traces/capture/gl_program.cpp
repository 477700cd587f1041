// GL program helpers; see gl_program.h.
#include "traces/capture/gl_program.h"

#include <fmt/format.h>

#include <stdexcept>

#include "nbsim_shaders.h"

namespace nbsim::capture {

GLuint compile_shader(GLenum type, const std::string& source, const char* name) {
  const GLuint s = glCreateShader(type);
  const char* src = source.c_str();
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    throw std::runtime_error(fmt::format("GLSL compile error in {}: {}", name, log));
  }
  return s;
}

GLuint link_program(std::initializer_list<GLuint> shaders, const char* name, bool capture_position, bool capture_point_size) {
  const GLuint p = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(p, s);
  if (capture_position) {
    const char* varyings[] = {"gl_Position", "gl_PointSize"};
    glTransformFeedbackVaryings(p, capture_point_size ? 2 : 1, varyings, GL_INTERLEAVED_ATTRIBS);
  }
  glLinkProgram(p);
  for (GLuint s : shaders) glDeleteShader(s);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    glDeleteProgram(p);
    throw std::runtime_error(fmt::format("GLSL link error in {}: {}", name, log));
  }
  return p;
}

void make_triangle_vertex_array(std::span<const float> xyz, std::span<const std::uint32_t> indices, GLuint& vao, GLuint& vbo,
                                GLuint& ebo) {
  glCreateVertexArrays(1, &vao);
  glCreateBuffers(1, &vbo);
  glCreateBuffers(1, &ebo);
  glNamedBufferStorage(vbo, static_cast<GLsizeiptr>(xyz.size_bytes()), xyz.data(), 0);
  glNamedBufferStorage(ebo, static_cast<GLsizeiptr>(indices.size_bytes()), indices.data(), 0);
  glVertexArrayVertexBuffer(vao, 0, vbo, 0, 3 * sizeof(float));
  glVertexArrayElementBuffer(vao, ebo);
  glEnableVertexArrayAttrib(vao, 0);
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 0, 0);
}

std::string covering_glsl(const CoveringSpec& spec) {
  return "#define COVERING_KIND " + std::to_string(static_cast<int>(spec.kind)) + "\n#define COVERING_TOP " +
         (spec.align == CoveringAlign::Top ? "1" : "0") + "\n" + shaders::common_covering_glsl;
}

std::string with_defines(const char* source, const std::string& defines) {
  std::string s(source);
  const auto eol = s.find('\n', s.find("#version"));
  return s.insert(eol + 1, defines);
}

}  // namespace nbsim::capture
