// The litmap passes on the CPU, the twin of shaders/shadows/litmap.* and splat.vert; see litmap.h.
#include "model/shadows/litmap.h"

#include <glm/matrix.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <future>
#include <string_view>
#include <thread>

#include "model/common/error.h"
#include "model/scene/technique_record.h"
#include "model/shadows/roles.h"
#include "model/shadows/volume.h"

namespace nbsim::shadows {

namespace {

// A window-to-NDC map of a w x h viewport with GL's [-1, 1] clip z: x * 2 / w - 1, likewise y,
// 2 z - 1.
glm::dmat4 window_to_ndc(int w, int h) {
  glm::dmat4 m(1.0);
  m[0][0] = 2.0 / static_cast<double>(w);
  m[1][1] = 2.0 / static_cast<double>(h);
  m[2][2] = 2.0;
  m[3] = glm::dvec4(-1.0, -1.0, -1.0, 1.0);
  return m;
}

// Window depth -> distance along the observer's view axis (litmap.frag's view_distance).
float view_distance(float d, float n, float f) {
  const float num = (2.0f * n) * f;
  const float den = (f + n) - ((2.0f * d - 1.0f) * (f - n));
  return num / den;
}

}  // namespace

glm::mat4 light_view_proj(const scene::Camera& light) {
  glm::mat4 view, proj;
  std::memcpy(&view[0][0], light.view.data(), 64);
  std::memcpy(&proj[0][0], light.proj.data(), 64);
  return proj * view;
}

std::array<std::array<float, 4>, 4> reprojection_rows(const glm::mat4& observer_view_proj, const glm::mat4& light_vp, int litmap_size) {
  const glm::dmat4 r = glm::dmat4(observer_view_proj) * glm::inverse(glm::dmat4(light_vp)) * window_to_ndc(litmap_size, litmap_size);
  std::array<std::array<float, 4>, 4> rows{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = static_cast<float>(r[j][i]);
  return rows;
}

LitmapReprojection::LitmapReprojection(const glm::mat4& observer_view_proj, const glm::mat4& light_vp, int litmap_size,
                                       const ReprojectSettings& settings, const DepthImage& observer)
    : rows_(reprojection_rows(observer_view_proj, light_vp, litmap_size)), settings_(settings), observer_(&observer) {
  // The 3x3 maximum, separably (max is associative): rows first, then columns, edges repeated.
  const int w = observer.width, h = observer.height;
  const auto at = [w](int x, int y) { return static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x); };
  std::vector<float> across(observer.texels.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      across[at(x, y)] = std::max({observer.texels[at(std::max(x - 1, 0), y)], observer.texels[at(x, y)],
                                   observer.texels[at(std::min(x + 1, w - 1), y)]});
  const float n = settings_.near_m, f = settings_.far_m, slack = 1.0f + settings_.tolerance_rel;
  unseen_beyond_.resize(observer.texels.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float farthest = std::max({0.0f, across[at(x, std::max(y - 1, 0))], across[at(x, y)], across[at(x, std::min(y + 1, h - 1))]});
      unseen_beyond_[at(x, y)] = view_distance(farthest, n, f) * slack + settings_.tolerance_m;
    }
}

bool LitmapReprojection::discards(int x, int y, float frag_z) const {
  const float fx = static_cast<float>(x) + 0.5f, fy = static_cast<float>(y) + 0.5f;
  std::array<float, 4> c{};
  for (std::size_t r = 0; r < 4; ++r) c[r] = ((rows_[r][0] * fx + rows_[r][1] * fy) + rows_[r][2] * frag_z) + rows_[r][3];
  if (!(c[3] > 0.0f)) return true;
  const float nx = c[0] / c[3], ny = c[1] / c[3], nz = c[2] / c[3];
  if (std::abs(nx) > 1.0f || std::abs(ny) > 1.0f || std::abs(nz) > 1.0f) return true;  // outside the observer's frustum
  const int w = observer_->width, h = observer_->height;
  const int px = std::clamp(static_cast<int>((nx * 0.5f + 0.5f) * static_cast<float>(w)), 0, w - 1);
  const int py = std::clamp(static_cast<int>((ny * 0.5f + 0.5f) * static_cast<float>(h)), 0, h - 1);
  return view_distance(nz * 0.5f + 0.5f, settings_.near_m, settings_.far_m) >
         unseen_beyond_[static_cast<std::size_t>(py) * static_cast<std::size_t>(w) + static_cast<std::size_t>(px)];
}

ReceiverSplat::ReceiverSplat(const glm::mat4& observer_view_proj, const glm::dmat4& light_clip, int width, int height) {
  const glm::dmat4 s = light_clip * glm::inverse(glm::dmat4(observer_view_proj)) * window_to_ndc(width, height);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) rows_[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = s[j][i];
}

std::optional<geometry::ClipPosition> ReceiverSplat::point(int x, int y, float d) const noexcept {
  if (d >= 1.0f) return std::nullopt;  // the far plane: no surface
  const double dx = static_cast<double>(x) + 0.5, dy = static_cast<double>(y) + 0.5, dd = static_cast<double>(d);
  std::array<double, 4> q{};
  for (std::size_t r = 0; r < 4; ++r) q[r] = ((rows_[r][0] * dx + rows_[r][1] * dy) + rows_[r][2] * dd) + rows_[r][3];
  if (!(q[3] > 0.0 && std::abs(q[0]) <= q[3] && std::abs(q[1]) <= q[3] && std::abs(q[2]) <= q[3])) return std::nullopt;
  const double inner = q[3] * (1.0 - 1.0 / 1048576.0);
  geometry::ClipPosition out{};
  for (std::size_t r = 0; r < 3; ++r) out[r] = static_cast<float>(std::min(std::max(q[r], -inner), inner));
  out[3] = static_cast<float>(q[3]);
  return out;
}

void ReceiverSplat::points(const DepthImage& observer, std::vector<geometry::ClipPosition>& out) const {
  for (int y = 0; y < observer.height; ++y)
    for (int x = 0; x < observer.width; ++x)
      if (const auto p = point(x, y, observer.at(x, y))) out.push_back(*p);
}

std::optional<LitmapMeshes> read_litmap_meshes(const scene::Frame& f) {
  const scene::TechniqueRecord* rec = nullptr;
  for (const scene::TechniqueRecord& r : f.technique_records)
    if (r.type == kLitmapMeshesRecordType) rec = &r;
  if (!rec) return std::nullopt;
  const std::uint64_t frame = f.begin.frame;
  const char* label = "ShadowLitmapMeshes (SHDM)";
  const auto& object = scene::record_field<std::uint32_t>(*rec, "object", label, frame);
  const auto& first = scene::record_field<std::uint32_t>(*rec, "first_triangle", label, frame);
  const auto& count = scene::record_field<std::uint32_t>(*rec, "triangle_count", label, frame);
  const auto& vertices = scene::record_field<float>(*rec, "vertices", label, frame);
  const auto& triangles = scene::record_field<std::uint32_t>(*rec, "triangles", label, frame);
  if (first.size() != object.size() || count.size() != object.size() || vertices.size() % 3 || triangles.size() % 3)
    throw InputError(fmt::format("frame {}: the {} record's fields do not agree in length", frame, label));
  LitmapMeshes m;
  for (std::size_t i = 0; i + 2 < vertices.size(); i += 3) m.vertices.emplace_back(vertices[i], vertices[i + 1], vertices[i + 2]);
  for (std::size_t i = 0; i + 2 < triangles.size(); i += 3) {
    for (std::size_t k = 0; k < 3; ++k)
      if (triangles[i + k] >= m.vertices.size())
        throw InputError(fmt::format("frame {}: the {} record's triangle {} names vertex {} of {}", frame, label, i / 3, triangles[i + k],
                                     m.vertices.size()));
    m.triangles.push_back({triangles[i], triangles[i + 1], triangles[i + 2]});
  }
  for (std::size_t o = 0; o < object.size(); ++o) {
    if (std::uint64_t{first[o]} + count[o] > m.triangles.size())
      throw InputError(fmt::format("frame {}: object {}'s triangles run past the {} record's", frame, object[o], label));
    if (object[o] >= (1u << 24)) throw InputError(fmt::format("frame {}: the {} record names object {}", frame, label, object[o]));
    if (object[o] >= m.range.size()) m.range.resize(object[o] + 1, {0, 0}), m.held.resize(object[o] + 1, false);
    if (m.held[object[o]]) throw InputError(fmt::format("frame {}: the {} record holds object {} twice", frame, label, object[o]));
    m.range[object[o]] = {first[o], count[o]};
    m.held[object[o]] = true;
  }
  return m;
}

DepthImage sampled_depth_image(const DepthImage& stored, raster::DepthFormat format) {
  if (format == raster::DepthFormat::Float32) return stored;
  DepthImage out = stored;
  const float scale = static_cast<float>(1.0 / 16777215.0);
  for (float& t : out.texels) t = static_cast<float>(std::llround(static_cast<double>(t) * 16777215.0)) * scale;
  return out;
}

int litmap_threads() {
  if (const char* env = std::getenv("NBSIM_SHADOWS_THREADS")) {
    const std::string_view v(env);
    if (v == "1") return 1;
    if (v == "2") return 2;
  }
  return std::thread::hardware_concurrency() >= 2 ? 2 : 1;
}

LitmapImages draw_litmaps(const scene::Frame& f, const LitmapMeshes& meshes, const LightFrustum& light_camera, int litmap_size,
                          const ReprojectSettings& settings, const DepthImage& depth, raster::RasterPathConfig path, bool compare_gl_counts, LitmapCounters& k) {
  if (!f.light) throw InputError(fmt::format("frame {}: no light camera (LGHT)", f.begin.frame));
  const glm::mat4 observer = observer_view_proj(f.begin);
  const glm::mat4 light = light_view_proj(*f.light);
  LitmapImages out{DepthImage(litmap_size, litmap_size, 1.0f), DepthImage(litmap_size, litmap_size, 0.0f)};
  path.width_px = path.height_px = litmap_size;
  path.depth_format = raster::DepthFormat::Float32;  // DEPTH_COMPONENT32F litmaps
  raster::RasterPath min_path(path, out.min), max_path(path, out.max);
  const LitmapReprojection reprojection(observer, light, litmap_size, settings, depth);
  // Every draw checked in draw order first (the first bad one is the one named), then each litmap's
  // draws in their order: the min and the max litmap are separate images, so with two host cores
  // they are drawn at once (the counts and images are the same either way); on one core, one after
  // the other, the receiver splats rasterized once for both (RasterPath::PointRaster).
  struct Item {
    const scene::DrawRecord* draw;
    raster::DrawState state;
  };
  std::vector<Item> items[2];  // [0]: the min litmap's draws, [1]: the max litmap's
  bool splats = false;
  for (const scene::DrawRecord& d : f.draws) {
    if (d.role != kLitmapRole && d.role != kReceiverSplatRole) continue;
    raster::DrawState state = raster::draw_state(d.state);
    const bool max = state.depth.func == raster::DepthFunc::Gequal;
    if (!max && state.depth.func != raster::DepthFunc::Lequal)
      throw InputError(fmt::format("frame {}: a {} draw with depth func {} (LEQUAL: min litmap, GEQUAL: max litmap)", f.begin.frame,
                                   d.role == kLitmapRole ? "litmap" : "receiver_splat", static_cast<int>(d.state.func)));
    if (d.role == kLitmapRole) {
      const auto o = static_cast<std::size_t>(d.object);
      if (d.object < 0 || o >= meshes.held.size() || !meshes.held[o])
        throw InputError(fmt::format("frame {}: litmap draw {} draws object {}, which the ShadowLitmapMeshes record does not hold",
                                     f.begin.frame, d.index, d.object));
      state.depth.shader = &reprojection;
    }
    splats = splats || d.role == kReceiverSplatRole;
    items[max ? 1 : 0].push_back({&d, state});
  }
  std::vector<geometry::ClipPosition> splat;  // the same points for both litmaps
  if (splats) ReceiverSplat(observer, light_camera.proj * light_camera.view, depth.width, depth.height).points(depth, splat);
  const auto draw_into = [&](raster::RasterPath& target, const std::vector<Item>& list, LitmapCounters& c,
                             raster::RasterPath::PointRaster* shared) {
    std::vector<geometry::ClipPosition> clip;
    std::vector<float> sizes;
    for (const Item& it : list) {
      const scene::DrawRecord& d = *it.draw;
      raster::DrawCounters dc;
      if (d.role == kLitmapRole) {
        clip.clear();
        const auto [first, count] = meshes.range[static_cast<std::size_t>(d.object)];
        for (std::uint32_t t = first; t < first + count; ++t)
          for (std::uint32_t v : meshes.triangles[t]) clip.push_back(clip_position(light, glm::vec4(meshes.vertices[v], 1.0f)));
        dc = target.draw(clip, it.state);
        ++c.draws;
        c.fragments += dc.depth.fragments;
        c.discarded += dc.depth.shader_discarded;
      } else {
        sizes.assign(splat.size(), 1.0f);
        dc = target.draw_points(splat, sizes, it.state, shared);
        c.splat_points += splat.size();
        c.splat_fragments += dc.depth.fragments;
      }
      if (compare_gl_counts && dc.depth.fragments != d.gl.fragments) ++c.fragment_diff;
    }
  };
  LitmapCounters counts[2];
  if (litmap_threads() >= 2 && !items[0].empty() && !items[1].empty()) {
    auto max_litmap = std::async(std::launch::async, [&] { draw_into(max_path, items[1], counts[1], nullptr); });
    draw_into(min_path, items[0], counts[0], nullptr);
    max_litmap.get();  // its error, if any, rethrown here
  } else {
    raster::RasterPath::PointRaster shared;  // rasterized once, tested into each litmap
    draw_into(min_path, items[0], counts[0], &shared);
    draw_into(max_path, items[1], counts[1], &shared);
  }
  for (const LitmapCounters& c : counts) {
    k.draws += c.draws, k.fragments += c.fragments, k.discarded += c.discarded;
    k.splat_points += c.splat_points, k.splat_fragments += c.splat_fragments, k.fragment_diff += c.fragment_diff;
  }
  return out;
}

}  // namespace nbsim::shadows
