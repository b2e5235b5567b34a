// Pixel-ownership images; see ownership.hpp.
#include "app/viz/ownership.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "app/viz/colour.hpp"

namespace viz {
namespace {

void check_size(int width, int height, std::size_t owners) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("ownership image: size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not positive");
  if (owners != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    throw std::invalid_argument("ownership image: " + std::to_string(owners) + " owners for " +
                                std::to_string(width) + "x" + std::to_string(height) + " pixels");
}

tracer::Color colour_for(std::uint16_t node) {
  const Rgb8 c = node_colour(node);
  return {c.r / 255.0f, c.g / 255.0f, c.b / 255.0f};
}

}  // namespace

tracer::Image ownership_image(int width, int height, const std::vector<std::uint16_t>& owners) {
  check_size(width, height, owners.size());
  tracer::Image img(width, height);
  std::size_t i = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) img.at(x, y) = colour_for(owners[i++]);
  return img;
}

tracer::Image ownership_overlay(const tracer::Image& rendered, const std::vector<std::uint16_t>& owners,
                                float weight) {
  check_size(rendered.width(), rendered.height(), owners.size());
  weight = std::clamp(weight, 0.0f, 1.0f);
  tracer::Image img(rendered.width(), rendered.height());
  std::size_t i = 0;
  for (int y = 0; y < rendered.height(); ++y)
    for (int x = 0; x < rendered.width(); ++x)
      img.at(x, y) = rendered.at(x, y) * (1.0f - weight) + colour_for(owners[i++]) * weight;
  return img;
}

}  // namespace viz
