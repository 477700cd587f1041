// The relief camera; see view.h.
#include "traces/capture/relief/view.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace nbsim::capture {

namespace {

glm::dmat4 map_matrix(int field_size, double box_height, double apex) {
  const double n = field_size, h = box_height;
  glm::dmat4 f(0.0);  // f[column][row]
  if (apex <= 0.0) {
    f[0][0] = n, f[1][1] = n, f[2][2] = 1.0 / h, f[3][3] = 1.0;
    return f;
  }
  // X = N (A x + z / 2), Y = N (A y + z / 2), Z = (h + A) / h z, W = z + A, A = apex * h: x / W runs
  // through the apex (0.5, 0.5, -A), z = 0 keeps x, the faces z = 0 and z = h land on 0 and 1.
  const double a = apex * h;
  f[0][0] = n * a, f[2][0] = 0.5 * n;
  f[1][1] = n * a, f[2][1] = 0.5 * n;
  f[2][2] = (h + a) / h;
  f[2][3] = 1.0, f[3][3] = a;
  return f;
}

}  // namespace

std::array<double, 16> frustum_map(int field_size, double box_height, double apex) {
  const glm::dmat4 f = map_matrix(field_size, box_height, apex);
  std::array<double, 16> out{};
  std::copy(glm::value_ptr(f), glm::value_ptr(f) + 16, out.begin());
  return out;
}

namespace {

std::array<double, 16> to_array(const glm::dmat4& m) {
  std::array<double, 16> out{};
  std::copy(glm::value_ptr(m), glm::value_ptr(m) + 16, out.begin());
  return out;
}

glm::dmat4 to_matrix(const std::array<double, 16>& a) { return glm::make_mat4(a.data()); }

}  // namespace

ReliefCamera relief_camera(int field_size, double box_height, double angle_deg, double azimuth_deg, int width, int height,
                           double apex) {
  const double th = glm::radians(angle_deg), ph = glm::radians(azimuth_deg);
  const glm::dmat4 f = map_matrix(field_size, box_height, apex);
  const glm::dmat4 to_world = glm::inverse(f);
  // The volume's corners in world space, its centre and bounding radius.
  glm::dvec3 corners[8], lo(1e300), hi(-1e300);
  for (int k = 0; k < 8; ++k) {
    const glm::dvec4 c = to_world * glm::dvec4((k & 1) ? field_size : 0, (k & 2) ? field_size : 0, (k & 4) ? 1.0 : 0.0, 1.0);
    corners[k] = glm::dvec3(c) / c.w;
    lo = glm::min(lo, corners[k]), hi = glm::max(hi, corners[k]);
  }
  const glm::dvec3 centre = 0.5 * (lo + hi);
  double radius = 0.0;
  for (const glm::dvec3& c : corners) radius = std::max(radius, glm::length(c - centre));
  const double distance = 2.5 * radius;
  const glm::dvec3 toward(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
  const glm::dvec3 eye = centre + distance * toward;
  const glm::dvec3 up(-std::cos(ph) * std::cos(th), -std::sin(ph) * std::cos(th), std::sin(th));
  const glm::dmat4 v = glm::lookAt(eye, centre, up);
  const double aspect = static_cast<double>(width) / height;
  const double fovy = 2.0 * std::asin(std::min(1.0, radius * 1.05 / distance)) * (aspect < 1.0 ? 1.0 / aspect : 1.0);
  const glm::dmat4 p = glm::perspective(fovy, aspect, distance - radius * 1.1, distance + radius * 1.1);
  return relief_view(to_array(v), to_array(p), to_array(f), width, height);
}

ReliefCamera relief_view(const std::array<double, 16>& view, const std::array<double, 16>& projection,
                         const std::array<double, 16>& world_to_texel, int width, int height) {
  const glm::dmat4 v = to_matrix(view), p = to_matrix(projection), f = to_matrix(world_to_texel);
  const glm::dmat4 to_clip = p * v * glm::inverse(f);
  const glm::dmat4 inv_pv = glm::inverse(p * v);
  const glm::dvec3 eye = glm::dvec3(glm::inverse(v)[3]);
  ReliefCamera c;
  for (std::size_t k = 0; k < 16; ++k) c.view.texel_to_clip[k] = static_cast<float>(glm::value_ptr(to_clip)[k]);
  c.world_view = view;
  c.projection = projection;
  c.eye_world = {eye.x, eye.y, eye.z};
  // The world point on the near plane through window point (px, py) (affine in (px, py)).
  const auto near_point = [&](double px, double py) {
    const glm::dvec4 w = inv_pv * glm::dvec4(2.0 * px / width - 1.0, 2.0 * py / height - 1.0, -1.0, 1.0);
    return glm::dvec3(w) / w.w;
  };
  relief::RayFrame& r = c.view.ray;
  const bool affine = f[0][3] == 0.0 && f[1][3] == 0.0 && f[2][3] == 0.0 && f[3][3] == 1.0;
  if (affine) {
    const glm::dvec3 origin = glm::dvec3(f * glm::dvec4(eye, 1.0));
    const auto direction = [&](double px, double py) { return glm::dvec3(f * glm::dvec4(near_point(px, py) - eye, 0.0)); };
    const glm::dvec3 d0 = direction(0, 0), dx = direction(1, 0) - d0, dy = direction(0, 1) - d0;
    for (int k = 0; k < 3; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      r.origin[kk] = static_cast<float>(origin[k]);
      r.a[kk] = static_cast<float>(dx[k]);
      r.b[kk] = static_cast<float>(dy[k]);
      r.c[kk] = static_cast<float>(d0[k]);
    }
  } else {
    r.frustum = true;
    const glm::dvec4 e = f * glm::dvec4(eye, 1.0);
    const auto q = [&](double px, double py) { return f * glm::dvec4(near_point(px, py), 1.0); };
    const glm::dvec4 q0 = q(0, 0), qx = q(1, 0) - q0, qy = q(0, 1) - q0;
    for (int k = 0; k < 4; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      r.eye_h[kk] = static_cast<float>(e[k]);
      r.qa[kk] = static_cast<float>(qx[k]);
      r.qb[kk] = static_cast<float>(qy[k]);
      r.qc[kk] = static_cast<float>(q0[k]);
    }
  }
  return c;
}

}  // namespace nbsim::capture
