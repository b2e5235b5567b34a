// Wire formats named once for both directions. A format is a field list in
// namespace nodes, in wire order: a function template wire_fields(v, x) that
// passes each field of x to v (an example at WireView below). put_fields()
// writes a value with it (BasicFieldWriter, over a const value) and get_fields()
// reads one back (FieldReader), so the two directions cannot disagree and a
// field added to the list travels both ways. How each kind of field travels
// is listed below; reading throws std::runtime_error (WireReader) where a
// message ends early.
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "nodes/ranks/transport.hpp"

namespace nodes {

// How one field travels (the encodings of WireWriter, transport.hpp):
//  - a type with its own wire_fields: its fields in their order, no framing
//    (a list wins over the raw bytes of a trivially copyable type);
//  - bool: one uint8, 1 or 0 (any non-zero byte reads as true);
//  - std::string, std::vector<T>: a uint64 count, then the elements: the
//    bytes of trivially copyable T without a list as one block, others one
//    by one by these rules;
//  - a C array: its elements in turn, no count;
//  - wire_as<W>(field): the field converted to W, read back and converted;
//  - wire_joined(bytes, more): two runs of bytes as one counted sequence,
//    read back into the first (the second left empty);
//  - wire_rest(span): the bytes to the end of the message, no count; last
//    only, and read as a view into the message;
//  - any other trivially copyable type: its sizeof bytes as in memory.

// The parameter of a field list: a T, const when written, not when read.
// A field list, for example:
//
//   template <class V>
//   void wire_fields(V& v, WireView<Tile> auto& t) { v(t.first); v(t.count); }
template <class T, class Of>
concept WireView = std::same_as<std::remove_const_t<T>, Of>;

// A field that travels in another form (the codecs above); each knows both
// directions itself.
template <class T>
concept WireCodec = requires(const T& codec, WireWriter& w) { codec.put_to(w); };

template <class Wire, class Field>
struct WireAs {
  Field& field;
  template <class Writer>
  void put_to(Writer& w) const { w.put(static_cast<Wire>(field)); }
  void get_from(WireReader& r) { field = static_cast<std::remove_const_t<Field>>(r.get<Wire>()); }
};

template <class Bytes, class More>
struct WireJoined {
  Bytes& first;
  More& second;
  template <class Writer>
  void put_to(Writer& w) const { w.put_joined(first, second); }
  void get_from(WireReader& r) {
    const std::span<const std::byte> bytes = r.get_counted_bytes();
    first.assign(bytes.begin(), bytes.end());
    second = {};
  }
};

template <class Span>
struct WireRest {
  Span& bytes;
  template <class Writer>
  void put_to(Writer& w) const { w.put_raw(bytes); }
  void get_from(WireReader& r) { bytes = r.take_rest(); }
};

template <class Wire, class Field>
WireAs<Wire, Field> wire_as(Field& field) {
  return {field};
}
template <class Bytes, class More>
WireJoined<Bytes, More> wire_joined(Bytes& first, More& second) {
  return {first, second};
}
template <class Span>
WireRest<Span> wire_rest(Span& bytes) {
  return {bytes};
}

// Found by argument-dependent lookup: the visitor is of namespace nodes, so
// field lists there describe types of any namespace.
template <class T, class Visitor>
concept HasWireFields = requires(Visitor& v, T& x) { wire_fields(v, x); };

namespace wire_detail {
template <class T>
inline constexpr bool is_vector = false;
template <class T, class A>
inline constexpr bool is_vector<std::vector<T, A>> = true;
}  // namespace wire_detail

template <class Writer>
class BasicFieldWriter {
 public:
  explicit BasicFieldWriter(Writer& w) : w_(w) {}

  template <class T>
  void operator()(const T& x) {
    if constexpr (WireCodec<T>) {
      x.put_to(w_);
    } else if constexpr (HasWireFields<const T, BasicFieldWriter>) {
      wire_fields(*this, x);
    } else if constexpr (std::is_same_v<T, bool>) {
      w_.template put<std::uint8_t>(x ? 1 : 0);
    } else if constexpr (std::is_same_v<T, std::string>) {
      w_.put_string(x);
    } else if constexpr (wire_detail::is_vector<T>) {
      put_sequence(x);
    } else if constexpr (std::is_array_v<T>) {
      for (const auto& element : x) (*this)(element);
    } else {
      static_assert(std::is_trivially_copyable_v<T>, "a field of this type needs a wire_fields list");
      w_.put(x);
    }
  }

 private:
  template <class T>
  void put_sequence(const std::vector<T>& xs) {
    static_assert(!std::is_same_v<T, bool>, "std::vector<bool> has no bytes to send");
    if constexpr (std::is_trivially_copyable_v<T> && !HasWireFields<const T, BasicFieldWriter>) {
      w_.put_vector(xs);
    } else {
      w_.template put<std::uint64_t>(xs.size());
      for (const T& x : xs) (*this)(x);
    }
  }

  Writer& w_;
};
using FieldWriter = BasicFieldWriter<WireWriter>;

class FieldReader {
 public:
  explicit FieldReader(WireReader& r) : r_(r) {}

  // Takes codecs as temporaries (wire_as(...)), everything else as a field.
  template <class T>
  void operator()(T&& x) {
    using U = std::remove_cvref_t<T>;
    if constexpr (WireCodec<U>) {
      x.get_from(r_);
    } else if constexpr (HasWireFields<U, FieldReader>) {
      wire_fields(*this, x);
    } else if constexpr (std::is_same_v<U, bool>) {
      x = r_.get<std::uint8_t>() != 0;
    } else if constexpr (std::is_same_v<U, std::string>) {
      x = r_.get_string();
    } else if constexpr (wire_detail::is_vector<U>) {
      get_sequence(x);
    } else if constexpr (std::is_array_v<U>) {
      for (auto& element : x) (*this)(element);
    } else {
      static_assert(std::is_trivially_copyable_v<U>, "a field of this type needs a wire_fields list");
      x = r_.get<U>();
    }
  }

 private:
  template <class T>
  void get_sequence(std::vector<T>& xs) {
    if constexpr (std::is_trivially_copyable_v<T> && !HasWireFields<T, FieldReader>) {
      xs = r_.get_vector<T>();
    } else {
      // An element takes at least one byte (a list with no fields has no
      // place in a sequence), so a count beyond what is left is refused
      // before anything is made.
      const auto n = r_.get<std::uint64_t>();
      r_.need(n);
      xs.clear();
      for (std::uint64_t i = 0; i < n; ++i) (*this)(xs.emplace_back());
    }
  }

  WireReader& r_;
};

template <class Buffer, class T>
void put_fields(BasicWireWriter<Buffer>& w, const T& x) {
  BasicFieldWriter<BasicWireWriter<Buffer>> v(w);
  v(x);
}

template <class T>
void get_fields(WireReader& r, T& x) {
  FieldReader v(r);
  v(x);
}

template <class T>
T get_fields(WireReader& r) {
  T x{};
  get_fields(r, x);
  return x;
}

}  // namespace nodes
