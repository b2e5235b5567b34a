// SVG and XML text for the viz library: escaping for the HTML report, and
// cairo's SVG documents made fit to be inlined in an HTML page.
// Invariants: inlinable_svg returns a document that starts with "<svg" (no
// XML declaration) and whose ids, with every reference to them, carry a
// prefix no other document of this process carries, so several pictures in
// one page never share an id.
#pragma once

#include <string>
#include <string_view>

namespace viz {

// Escapes & < > " ' for element text and attribute values alike.
std::string escape_xml(std::string_view text);

// `svg`, a whole document as cairo writes it, without its XML declaration
// and with every id="x", url(#x) and href="#x" made unique to this call.
std::string inlinable_svg(std::string_view svg);

}  // namespace viz
