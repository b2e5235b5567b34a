// Pixel-ownership pictures: which node computed each pixel, one stable
// colour per node (node_colour in colour.hpp), optionally blended over the
// rendered image so the scene stays recognisable, and the picture of such an
// image with its key beside or under it (drawn with cairo).
// Invariants: pixel (x, y) takes owners[y * width + x]; a node's colour does
// not depend on the node count, the image size or the other owners; the key
// shows every entry's colour as a solid swatch.
#pragma once

#include <cstdint>
#include <vector>

#include "app/viz/html_report.hpp"
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

// `ownership` enlarged by a whole factor to at least 256 px wide (pixels kept
// sharp), at the top left, with `key` beside it (a swatch and its label per
// entry, in columns) or, when that would take more than four columns, under
// it; a key of more than 256 entries is compact: rows of small swatches,
// each row labelled by its first entry. Throws std::invalid_argument for an
// empty image or a picture over 16384 px a side.
tracer::Image ownership_picture(const tracer::Image& ownership, const std::vector<KeyEntry>& key);

}  // namespace viz
