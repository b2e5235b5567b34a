// Payload's move assignment (packet.hpp), out of line: inlined into a
// caller that builds a payload of known size, GCC's object-size analysis
// takes the inline buffer's copy for an overread and warns.
#include "nodes/net/packet.hpp"

#include <memory>
#include <utility>

namespace nodes {

Payload& Payload::operator=(Payload&& other) noexcept {
  if (this != &other) {
    std::destroy_at(this);
    std::construct_at(this, std::move(other));
  }
  return *this;
}

}  // namespace nodes
