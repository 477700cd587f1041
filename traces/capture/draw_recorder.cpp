// The draw recorder; see draw_recorder.h.
#include "traces/capture/draw_recorder.h"

#include <algorithm>

#include "model/common/error.h"

namespace nbsim::capture {

namespace {

// Grows a buffer to hold at least `need` bytes, keeping its contents (zero past them).
void grow(GLuint& buffer, std::size_t& capacity, std::size_t need) {
  if (need <= capacity) return;
  const std::size_t size = std::max(need, capacity * 2);
  GLuint b = 0;
  glCreateBuffers(1, &b);
  glNamedBufferStorage(b, static_cast<GLsizeiptr>(size), nullptr, GL_DYNAMIC_STORAGE_BIT);
  const GLuint zero = 0;
  glClearNamedBufferData(b, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  if (capacity) glCopyNamedBufferSubData(buffer, b, 0, 0, static_cast<GLsizeiptr>(capacity));
  glDeleteBuffers(1, &buffer);
  buffer = b;
  capacity = size;
}

}  // namespace

scene::DepthState depth_state(bool reversed, bool write, bool test) {
  scene::DepthState s;
  s.func = reversed ? scene::DepthFunc::Greater : scene::DepthFunc::Less;
  s.write = write;
  s.test = test;
  s.cull = scene::CullFace::Back;
  s.front_ccw = true;
  s.clip = reversed ? scene::ClipControl::ZeroToOne : scene::ClipControl::NegativeOneToOne;
  return s;
}

DrawRecorder::DrawRecorder() {
  glGenTransformFeedbacks(1, &tf_object_);
  glCreateBuffers(1, &counts_ssbo_);
  glCreateBuffers(1, &tf_buffer_);
}

DrawRecorder::~DrawRecorder() {
  const GLuint buffers[] = {counts_ssbo_, tf_buffer_};
  glDeleteBuffers(2, buffers);
  glDeleteTransformFeedbacks(1, &tf_object_);
  for (auto* pool : {&q_samples_, &q_clip_in_, &q_clip_out_}) glDeleteQueries(static_cast<GLsizei>(pool->size()), pool->data());
}

void DrawRecorder::reserve(std::size_t draw_count, std::size_t tf_bytes) {
  std::size_t bytes = counts_capacity_ * 4;
  if (draw_count * 4 > bytes) {
    grow(counts_ssbo_, bytes, draw_count * 4);
    counts_capacity_ = bytes / 4;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts_ssbo_);
  }
  grow(tf_buffer_, tf_capacity_, tf_bytes);
  while (q_samples_.size() < draw_count) {
    GLuint q[3];
    glGenQueries(3, q);
    q_samples_.push_back(q[0]);
    q_clip_in_.push_back(q[1]);
    q_clip_out_.push_back(q[2]);
  }
}

void DrawRecorder::begin_frame(std::size_t expected_draws) {
  draws_.clear();
  pending_.clear();
  tf_used_ = 0;
  reserve(expected_draws, 0);
  const GLuint zero = 0;
  glClearNamedBufferData(counts_ssbo_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
}

void DrawRecorder::bind() const {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts_ssbo_);
  glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, tf_object_);
}

std::size_t DrawRecorder::begin_draw(scene::DrawRecord record, std::size_t captured_vertices, GLenum primitive) {
  const std::size_t slot = draws_.size();
  const std::size_t floats = primitive == GL_POINTS ? 5 : 4;  // one vec4 a vertex (and a point size)
  const std::size_t bytes = captured_vertices * floats * 4;
  reserve(slot + 1, tf_used_ + bytes);
  record.index = static_cast<std::uint32_t>(slot);
  if (primitive == GL_POINTS) record.topology = scene::Topology::Points;
  draws_.push_back(std::move(record));
  pending_.push_back({true, bytes > 0, tf_used_, bytes, floats});
  if (bytes > 0) {
    glBindBufferRange(GL_TRANSFORM_FEEDBACK_BUFFER, 0, tf_buffer_, static_cast<GLintptr>(tf_used_), static_cast<GLsizeiptr>(bytes));
    tf_used_ += bytes;
  }
  // llvmpipe (Mesa 22.3) miscounts a GL_SAMPLES_PASSED query when its scene is flushed between
  // BeginQuery and EndQuery (measured: at 1600x1200, from about the 400th query-wrapped draw of a scene
  // on, e.g. a hidden draw of 43 fragments reported 102,365 samples): the scene fills up, and every
  // query puts its begin and end commands into every 64x64 bin. So the recorder flushes, outside any
  // query, before the draws of a scene times its bins exceed kFlushBinDraws (a sixth of where the
  // miscount began; 512x512: every 512 draws, 1600x1200: every 68). Flushing before every draw also
  // works but triples GL's time on a 512x512 city frame.
  GLint viewport[4] = {0, 0, 0, 0};
  glGetIntegerv(GL_VIEWPORT, viewport);
  const std::uint64_t bins = static_cast<std::uint64_t>((std::max(viewport[2], 1) + 63) / 64) *
                             static_cast<std::uint64_t>((std::max(viewport[3], 1) + 63) / 64);
  if (scene_bin_draws_ + bins > kFlushBinDraws) {
    glFlush();
    scene_bin_draws_ = 0;
  }
  scene_bin_draws_ += bins;
  glBeginQuery(GL_SAMPLES_PASSED, q_samples_[slot]);
  glBeginQuery(GL_CLIPPING_INPUT_PRIMITIVES, q_clip_in_[slot]);
  glBeginQuery(GL_CLIPPING_OUTPUT_PRIMITIVES, q_clip_out_[slot]);
  if (bytes > 0) glBeginTransformFeedback(primitive);
  return slot;
}

void DrawRecorder::end_draw() {
  NBSIM_CHECK(!pending_.empty() && pending_.back().gl_draw, "end_draw() without begin_draw()");
  if (pending_.back().capturing) glEndTransformFeedback();
  glEndQuery(GL_CLIPPING_OUTPUT_PRIMITIVES);
  glEndQuery(GL_CLIPPING_INPUT_PRIMITIVES);
  glEndQuery(GL_SAMPLES_PASSED);
}

std::size_t DrawRecorder::add_record(scene::DrawRecord record) {
  const std::size_t slot = draws_.size();
  record.index = static_cast<std::uint32_t>(slot);
  draws_.push_back(std::move(record));
  pending_.push_back({false, false, 0, 0});  // no GL draw: no counters to read
  return slot;
}

std::uint64_t DrawRecorder::samples_passed(std::size_t slot) const {
  NBSIM_CHECK(slot < pending_.size() && pending_[slot].gl_draw, "samples_passed() of a slot without a GL draw");
  GLuint64 v = 0;
  glGetQueryObjectui64v(q_samples_[slot], GL_QUERY_RESULT, &v);
  return v;
}

std::uint32_t DrawRecorder::scratch_slot() {
  reserve(draws_.size() + 1, 0);
  return static_cast<std::uint32_t>(counts_capacity_ - 1);
}

std::vector<scene::DrawRecord> DrawRecorder::collect() {
  scene_bin_draws_ = 0;  // reading the results flushes the scene
  std::vector<std::uint32_t> counts(draws_.size());
  if (!draws_.empty()) glGetNamedBufferSubData(counts_ssbo_, 0, static_cast<GLsizeiptr>(counts.size() * 4), counts.data());
  std::vector<float> tf(tf_used_ / 4);
  if (tf_used_) glGetNamedBufferSubData(tf_buffer_, 0, static_cast<GLsizeiptr>(tf_used_), tf.data());
  for (std::size_t i = 0; i < draws_.size(); ++i) {
    scene::DrawRecord& d = draws_[i];
    const Pending& p = pending_[i];
    if (!p.gl_draw) continue;
    d.gl.fragments = counts[i];
    glGetQueryObjectui64v(q_samples_[i], GL_QUERY_RESULT, &d.gl.samples_passed);
    glGetQueryObjectui64v(q_clip_in_[i], GL_QUERY_RESULT, &d.gl.clip_prims_in);
    glGetQueryObjectui64v(q_clip_out_[i], GL_QUERY_RESULT, &d.gl.clip_prims_out);
    for (std::size_t b = p.tf_offset; b < p.tf_offset + p.tf_bytes; b += p.floats_per_vertex * 4) {
      d.clip_positions.push_back({tf[b / 4], tf[b / 4 + 1], tf[b / 4 + 2], tf[b / 4 + 3]});
      if (p.floats_per_vertex == 5) d.point_sizes.push_back(tf[b / 4 + 4]);
    }
  }
  std::vector<scene::DrawRecord> out = std::move(draws_);
  draws_.clear();
  pending_.clear();
  tf_used_ = 0;
  return out;
}

}  // namespace nbsim::capture
