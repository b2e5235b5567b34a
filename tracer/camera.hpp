// The NFF pinhole camera. `angle` is the full field of view between the centres
// of the first and last pixel columns (and rows; pixels are square, the larger
// image dimension fixes the scale). Image coordinates: x right, y down, pixel
// (x, y) centred at (x, y); SPD corner samples sit at (x - 0.5, y - 0.5).
// Eye-ray directions are not normalised: their component along the view axis
// is 1, so a distance t along them is the depth used for the hither plane.
#pragma once

#include "tracer/geometry.hpp"
#include "tracer/scene.hpp"

namespace tracer {

class CameraModel {
 public:
  explicit CameraModel(const Camera& camera);
  // Eye ray through the image point (px, py), computed in double then rounded.
  Ray ray_through(double px, double py) const;
  float hither() const { return hither_; }

 private:
  Vec3d origin_, forward_, right_, down_;  // right_/down_ scaled to one pixel
  double cx_, cy_;                         // image centre in pixel coordinates
  float hither_;
};

}  // namespace tracer
