// The relief camera; see view.h.
#include "traces/capture/relief/view.h"

#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace nbsim::capture {

ReliefCamera relief_camera(int field_size, double box_height, double angle_deg, double azimuth_deg, int width, int height) {
  const double n = field_size;
  const double th = glm::radians(angle_deg), ph = glm::radians(azimuth_deg);
  const glm::dvec3 centre(0.5, 0.5, box_height * 0.5);
  const double radius = glm::length(glm::dvec3(0.5, 0.5, box_height * 0.5));
  const double distance = 2.5 * radius;
  const glm::dvec3 toward(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
  const glm::dvec3 eye = centre + distance * toward;
  const glm::dvec3 up(-std::cos(ph) * std::cos(th), -std::sin(ph) * std::cos(th), std::sin(th));
  const glm::dmat4 v = glm::lookAt(eye, centre, up);
  const double aspect = static_cast<double>(width) / height;
  const double fovy = 2.0 * std::asin(std::min(1.0, radius * 1.05 / distance)) * (aspect < 1.0 ? 1.0 / aspect : 1.0);
  const glm::dmat4 p = glm::perspective(fovy, aspect, distance - radius * 1.1, distance + radius * 1.1);
  // Texel space to world: x / N, y / N, z * box_height.
  const glm::dmat4 m = glm::scale(glm::dmat4(1.0), glm::dvec3(1.0 / n, 1.0 / n, box_height));
  const glm::dmat4 to_clip = p * v * m;
  const glm::dmat4 inv_pv = glm::inverse(p * v);
  const glm::dmat4 inv_m = glm::inverse(m);

  ReliefCamera c;
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      c.view.texel_to_clip[static_cast<std::size_t>(col * 4 + row)] = static_cast<float>(to_clip[col][row]);
      c.world_view[static_cast<std::size_t>(col * 4 + row)] = v[col][row];
      c.projection[static_cast<std::size_t>(col * 4 + row)] = p[col][row];
    }
  c.eye_world = {eye.x, eye.y, eye.z};
  const glm::dvec3 origin = glm::dvec3(inv_m * glm::dvec4(eye, 1.0));
  // The direction through window point (px, py): the near-plane point minus the eye, in texel space
  // (affine in (px, py) for a perspective camera).
  const auto direction = [&](double px, double py) {
    const glm::dvec4 ndc(2.0 * px / width - 1.0, 2.0 * py / height - 1.0, -1.0, 1.0);
    glm::dvec4 w = inv_pv * ndc;
    const glm::dvec3 q = glm::dvec3(w) / w.w;
    return glm::dvec3(inv_m * glm::dvec4(q - eye, 0.0));
  };
  const glm::dvec3 d0 = direction(0, 0), dx = direction(1, 0) - d0, dy = direction(0, 1) - d0;
  for (int k = 0; k < 3; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    c.origin[kk] = origin[k];
    c.a[kk] = dx[k];
    c.b[kk] = dy[k];
    c.c[kk] = d0[k];
    c.view.ray.origin[kk] = static_cast<float>(origin[k]);
    c.view.ray.a[kk] = static_cast<float>(dx[k]);
    c.view.ray.b[kk] = static_cast<float>(dy[k]);
    c.view.ray.c[kk] = static_cast<float>(d0[k]);
  }
  return c;
}

}  // namespace nbsim::capture
