// Colour legends (see legend.hpp).
#include "app/viz/legend.hpp"

#include "app/viz/ticks.hpp"

namespace viz {

void scale_gradient(SvgDocument& doc, const std::string& id, Rgb8 (*scale)(double)) {
  doc.open("linearGradient", {{"id", id}});
  for (int i = 0; i <= 10; ++i)
    doc.leaf("stop", {{"offset", num(i / 10.0)}, {"stop-color", hex(scale(i / 10.0))}});
  doc.close();
}

void colour_bar(SvgDocument& doc, double x, double y, const std::string& id, const std::string& caption,
                double max) {
  doc.text(caption, {{"x", num(x)}, {"y", num(y)}, {"font-size", "12"}});
  doc.leaf("rect", {{"x", num(x)}, {"y", num(y + 6)}, {"width", "160"}, {"height", "10"},
                    {"fill", "url(#" + id + ")"}, {"stroke", "#333333"}});
  doc.text("0", {{"x", num(x)}, {"y", num(y + 30)}, {"font-size", "11"}});
  doc.text(format_number(max), {{"x", num(x + 160)}, {"y", num(y + 30)}, {"font-size", "11"}, {"text-anchor", "end"}});
}

}  // namespace viz
