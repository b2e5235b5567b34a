// nodes::Transport: the wire between the OS processes (ranks) of a machine
// split over several processes. The machine sends only byte strings through
// it; MPI carries them between processes and hosts (mpi/mpi_transport.hpp),
// LocalTransportGroup between ranks that are threads of one process, so the
// ordinary test suite can split a machine without a launcher.
//
// Contract (what the machine relies on, and both implementations give):
//  - post() and poll() never block: a fiber may call them (a fiber that
//    blocked inside the wire would stall its whole thread).
//  - Messages from one rank to another on one tag arrive in the order they
//    were posted, each once, whole (order holds within a tag only).
//  - A posted message belongs to the transport; progress() moves pending
//    sends on and pending() counts those not yet complete. A rank ends only
//    once pending() is 0.
//  - All calls on one Transport come from one thread at a time.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace nodes {

using Bytes = std::vector<std::byte>;

// The uses of the wire; each keeps its own order.
enum class Tag : int { setup = 1, bridge = 2, report = 3, clock = 4 };

struct Incoming {
  int from = 0;
  Bytes bytes;
};

class Transport {
 public:
  virtual ~Transport() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  virtual void post(int to, Tag tag, Bytes message) = 0;
  virtual std::optional<Incoming> poll(Tag tag) = 0;
  virtual void progress() = 0;
  virtual std::size_t pending() const = 0;

  // For the set-up and the gathering of reports, outside any process: waits,
  // sleeping between polls so that a waiting rank leaves its core idle, for
  // a message on `tag` from `from` (any rank if negative). Messages from
  // other ranks that arrive meanwhile are kept for later calls.
  Incoming receive(Tag tag, int from = -1);
  // Waits until every posted message is complete.
  void flush();

 private:
  std::vector<std::deque<Incoming>> early_;  // per tag, messages receive() set aside
};

// Several ranks inside one process, one Transport each; each rank's calls
// come from its own thread. Sends complete at once (the bytes are moved into
// the receiver's queue).
class LocalTransportGroup {
 public:
  explicit LocalTransportGroup(int ranks);
  ~LocalTransportGroup();
  Transport& rank(int r);
  int size() const;

 private:
  struct Shared;
  class Endpoint;
  std::shared_ptr<Shared> shared_;
  std::vector<std::unique_ptr<Endpoint>> endpoints_;
};

// Flat encoding of messages: values of trivially copyable types as their
// bytes (every rank runs the same binary on the same architecture),
// sequences with a 64-bit count before them. Reader throws
// std::runtime_error on a message shorter than what is read from it.
// Structured values are written and read by their field lists
// (wire_fields.hpp). A writer appends to its Buffer, which has size,
// resize and data: its own Bytes between ranks, or (Buffer a reference) a
// packet's payload in place (messages.cpp).
template <class Buffer>
class BasicWireWriter {
 public:
  BasicWireWriter() = default;
  explicit BasicWireWriter(Buffer into) : bytes_(into) {}

  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    append(&value, sizeof(T));
  }
  template <class T>
  void put_vector(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    put<std::uint64_t>(values.size());
    append(values.data(), values.size() * sizeof(T));
  }
  // Two runs of bytes as one sequence, read back by get_vector<std::byte>.
  void put_joined(std::span<const std::byte> first, std::span<const std::byte> second) {
    put<std::uint64_t>(first.size() + second.size());
    append(first.data(), first.size());
    append(second.data(), second.size());
  }
  void put_string(const std::string& s) {
    put<std::uint64_t>(s.size());
    append(s.data(), s.size());
  }
  // Bytes with no count: the end of a message, read back by take_rest().
  void put_raw(std::span<const std::byte> bytes) { append(bytes.data(), bytes.size()); }
  void reserve(std::size_t n) { bytes_.reserve(n); }
  Buffer take() { return std::move(bytes_); }
  std::size_t size() const { return bytes_.size(); }

 private:
  void append(const void* data, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, data, n);
  }
  Buffer bytes_;
};
using WireWriter = BasicWireWriter<Bytes>;

class WireReader {
 public:
  // Reads `bytes` in place: they must outlive the reader and what
  // take_rest() returns.
  explicit WireReader(std::span<const std::byte> bytes) : bytes_(bytes) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  template <class T>
  std::vector<T> get_vector() {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto n = get<std::uint64_t>();
    if (n > (bytes_.size() - at_) / std::max<std::size_t>(sizeof(T), 1)) fail();
    std::vector<T> values(n);
    if (n) std::memcpy(values.data(), take(n * sizeof(T)), n * sizeof(T));
    return values;
  }
  std::string get_string();
  // A count, then that many bytes, viewed in place.
  std::span<const std::byte> get_counted_bytes() {
    const auto n = get<std::uint64_t>();
    return {take(static_cast<std::size_t>(n)), static_cast<std::size_t>(n)};
  }
  // All that is left, as a view into the message.
  std::span<const std::byte> take_rest() { return bytes_.subspan(std::exchange(at_, bytes_.size())); }
  // Throws unless at least n bytes are left.
  void need(std::uint64_t n) const {
    if (n > bytes_.size() - at_) fail();
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  const std::byte* take(std::size_t n);
  [[noreturn]] static void fail();
  std::span<const std::byte> bytes_;
  std::size_t at_ = 0;
};

}  // namespace nodes
