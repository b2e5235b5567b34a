// Mailbox process (see mailbox.hpp).
#include "nodes/net/mailbox.hpp"

namespace nodes {

void Mailbox::forward(csp::In<Packet> port) const {
  auto out = buffer_.writer();
  for (;;) out.write(port.read());  // ends with csp::Poisoned at shutdown
}

}  // namespace nodes
