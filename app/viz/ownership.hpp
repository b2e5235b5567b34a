// Pixel-ownership pictures: which node computed each pixel, one stable
// colour per node (node_colour in colour.hpp), optionally blended over the
// rendered image so the scene stays recognisable.
// Invariants: pixel (x, y) takes owners[y * width + x]; a node's colour does
// not depend on the node count, the image size or the other owners.
#pragma once

#include <cstdint>
#include <vector>

#include "tracer/image.hpp"

namespace viz {

// Throws std::invalid_argument if width or height is not positive or
// owners.size() != width * height.
tracer::Image ownership_image(int width, int height, const std::vector<std::uint16_t>& owners);

// The rendered image with each pixel mixed towards its owner's colour:
// result = (1 - weight) * rendered + weight * owner colour, weight in [0, 1].
// Throws std::invalid_argument if owners does not match the image size.
tracer::Image ownership_overlay(const tracer::Image& rendered, const std::vector<std::uint16_t>& owners,
                                float weight = 0.5f);

}  // namespace viz
