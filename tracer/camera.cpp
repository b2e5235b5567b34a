// NFF camera: orthonormal frame from (from, at, up), pixel step from the angle.
#include "tracer/camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tracer {

CameraModel::CameraModel(const Camera& c)
    : origin_(c.from), cx_((c.width - 1) * 0.5), cy_((c.height - 1) * 0.5),
      hither_(static_cast<float>(c.hither)) {
  forward_ = normalize(c.at - c.from);
  // up need not be perpendicular to the view direction: Gram-Schmidt via cross products.
  const Vec3d right = normalize(cross(forward_, c.up));
  const Vec3d up = cross(right, forward_);
  const double half = std::tan(c.angle_deg * std::numbers::pi / 360.0);
  const double span = std::max(1, std::max(c.width, c.height) - 1);
  const double step = 2.0 * half / span;
  right_ = right * step;
  down_ = up * -step;
}

Ray CameraModel::ray_through(double px, double py) const {
  const Vec3d d = forward_ + right_ * (px - cx_) + down_ * (py - cy_);
  return {static_cast<Vec3f>(origin_), static_cast<Vec3f>(d)};
}

}  // namespace tracer
