// Helpers of the wire-format tests (messages, packets, reports): values
// whose every field differs from its default, exact comparison of values
// that travel as their bytes, the bytes a format promises written out by
// hand, and the check that a message cut short anywhere is refused.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstddef>
#include <cstring>
#include <span>
#include <stdexcept>
#include <type_traits>

#include "nodes/net/packet.hpp"
#include "nodes/ranks/transport.hpp"

namespace wire_test {

// A value whose byte i is seed + i: no byte is 0 (seed >= 1 and the bytes
// stop short of 256), so every field differs from its default, and values
// of different seeds differ. Only for types whose bytes are all fields
// (the tests assert their sizes).
template <class T>
T patterned(unsigned seed) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (seed == 0 || seed + sizeof(T) > 256) throw std::logic_error("patterned: seed out of range for the size");
  std::array<unsigned char, sizeof(T)> bytes;
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<unsigned char>(seed + i);
  return std::bit_cast<T>(bytes);
}

template <class T>
bool same_bytes(const T& a, const T& b) {
  static_assert(std::is_trivially_copyable_v<T>);
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// The values' bytes one after another, as WireWriter::put writes each.
template <class... T>
nodes::Bytes raw(const T&... values) {
  nodes::WireWriter w;
  (w.put(values), ...);
  return w.take();
}

// Replaces the bytes at `at` with `with` (to forge a field of a message).
inline void overwrite(nodes::Bytes& bytes, std::size_t at, const nodes::Bytes& with) {
  if (at + with.size() > bytes.size()) throw std::logic_error("overwrite: beyond the message");
  std::memcpy(bytes.data() + at, with.data(), with.size());
}

// A packet's payload as the plain bytes the expectations are written in.
inline nodes::Bytes bytes_of(const nodes::Payload& payload) { return nodes::Bytes(payload.begin(), payload.end()); }

inline nodes::Bytes joined(nodes::Bytes first, std::span<const std::byte> second) {
  first.insert(first.end(), second.begin(), second.end());
  return first;
}

// decode(prefix) throws std::runtime_error for every prefix of `bytes`
// from `shortest` bytes up to one byte short of the whole.
template <class Decode>
void expect_prefixes_refused(std::span<const std::byte> bytes, Decode decode, std::size_t shortest = 0) {
  for (std::size_t n = shortest; n < bytes.size(); ++n)
    EXPECT_THROW(decode(bytes.first(n)), std::runtime_error) << "a message cut to " << n << " of " << bytes.size();
}

}  // namespace wire_test
