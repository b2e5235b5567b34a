// Table 2 of the paper, as printed (h, mn, s), on 1 to 64 nodes; see paper_figures.hpp.
#include "app/experiments/paper_figures.hpp"

#include <array>

namespace app {
namespace {

constexpr int hms(int h, int mn, int s) { return 3600 * h + 60 * mn + s; }

struct Row {
  std::string_view scene;
  std::array<int, 7> seconds;  // N = 1, 2, 4, ..., 64; 0 where the paper has no figure
};

constexpr Row table2[] = {
    {"teapot",
     {hms(3, 12, 2), hms(1, 39, 57), hms(0, 51, 32), hms(0, 26, 5), hms(0, 13, 6), hms(0, 6, 35), hms(0, 3, 20)}},
    {"mountain",
     {hms(4, 45, 3), hms(2, 30, 38), hms(1, 17, 6), hms(0, 39, 10), hms(0, 19, 45), hms(0, 10, 0), hms(0, 5, 7)}},
    {"rings4", {0, hms(4, 58, 46), hms(2, 33, 24), hms(1, 17, 35), hms(0, 38, 56), hms(0, 19, 41), hms(0, 10, 4)}},
    {"tetra9", {0, 0, 0, 0, hms(0, 4, 55), hms(0, 2, 26), hms(0, 1, 18)}},
    {"tetra10", {0, 0, 0, 0, 0, 0, hms(0, 3, 46)}},
};

}  // namespace

std::optional<double> paper_synthesis_seconds(std::string_view scene, int width, int height, int nodes) {
  if (width != 512 || height != 512) return std::nullopt;
  int column = 0;
  while (column < 7 && (1 << column) != nodes) ++column;
  if (column == 7) return std::nullopt;
  for (const Row& row : table2)
    if (row.scene == scene && row.seconds[column] > 0) return row.seconds[column];
  return std::nullopt;
}

}  // namespace app
