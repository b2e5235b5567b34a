// Transport's waiting helpers, the in-process transport and the wire encoding.
#include "nodes/ranks/transport.hpp"

#include <algorithm>
#include <thread>

namespace nodes {

namespace {
std::size_t tag_index(Tag tag) { return static_cast<std::size_t>(tag); }
}  // namespace

Incoming Transport::receive(Tag tag, int from) {
  if (early_.size() <= tag_index(tag)) early_.resize(tag_index(tag) + 1);
  auto& early = early_[tag_index(tag)];
  const auto wanted = [from](const Incoming& m) { return from < 0 || m.from == from; };
  // A message waits for us only while we are not looking: poll every
  // 50 us at first, backing off to 2 ms, so a long wait costs no core.
  auto nap = std::chrono::microseconds(50);
  for (;;) {
    if (auto it = std::find_if(early.begin(), early.end(), wanted); it != early.end()) {
      Incoming m = std::move(*it);
      early.erase(it);
      return m;
    }
    progress();
    if (auto m = poll(tag)) {
      if (wanted(*m)) return std::move(*m);
      early.push_back(std::move(*m));
      continue;
    }
    std::this_thread::sleep_for(nap);
    nap = std::min(nap * 2, std::chrono::microseconds(2000));
  }
}

void Transport::flush() {
  auto nap = std::chrono::microseconds(20);
  for (progress(); pending() > 0; progress()) {
    std::this_thread::sleep_for(nap);
    nap = std::min(nap * 2, std::chrono::microseconds(2000));
  }
}

// ---- LocalTransportGroup ----

struct LocalTransportGroup::Shared {
  std::mutex mutex;
  // [to][tag]: messages posted to rank `to`, in order.
  std::vector<std::vector<std::deque<Incoming>>> queues;
};

class LocalTransportGroup::Endpoint final : public Transport {
 public:
  Endpoint(std::shared_ptr<Shared> shared, int rank) : shared_(std::move(shared)), rank_(rank) {}
  int rank() const override { return rank_; }
  int size() const override { return static_cast<int>(shared_->queues.size()); }
  void post(int to, Tag tag, Bytes message) override {
    if (to < 0 || to >= size() || to == rank_)
      throw std::out_of_range("transport: rank " + std::to_string(rank_) + " cannot post to rank " +
                              std::to_string(to));
    std::lock_guard<std::mutex> lk(shared_->mutex);
    auto& queues = shared_->queues[static_cast<std::size_t>(to)];
    if (queues.size() <= tag_index(tag)) queues.resize(tag_index(tag) + 1);
    queues[tag_index(tag)].push_back(Incoming{rank_, std::move(message)});
  }
  std::optional<Incoming> poll(Tag tag) override {
    std::lock_guard<std::mutex> lk(shared_->mutex);
    auto& queues = shared_->queues[static_cast<std::size_t>(rank_)];
    if (queues.size() <= tag_index(tag) || queues[tag_index(tag)].empty()) return std::nullopt;
    Incoming m = std::move(queues[tag_index(tag)].front());
    queues[tag_index(tag)].pop_front();
    return m;
  }
  void progress() override {}
  std::size_t pending() const override { return 0; }

 private:
  std::shared_ptr<Shared> shared_;
  int rank_;
};

LocalTransportGroup::LocalTransportGroup(int ranks) : shared_(std::make_shared<Shared>()) {
  if (ranks < 1) throw std::invalid_argument("transport: a group needs at least one rank");
  shared_->queues.resize(static_cast<std::size_t>(ranks));
  for (int r = 0; r < ranks; ++r) endpoints_.push_back(std::make_unique<Endpoint>(shared_, r));
}

LocalTransportGroup::~LocalTransportGroup() = default;

Transport& LocalTransportGroup::rank(int r) { return *endpoints_.at(static_cast<std::size_t>(r)); }
int LocalTransportGroup::size() const { return static_cast<int>(endpoints_.size()); }

// ---- wire encoding ----

std::string WireReader::get_string() {
  const auto n = get<std::uint64_t>();
  if (n > bytes_.size() - at_) fail();
  const auto* p = reinterpret_cast<const char*>(take(n));
  return std::string(p, p + n);
}

const std::byte* WireReader::take(std::size_t n) {
  if (n > bytes_.size() - at_) fail();
  const std::byte* p = bytes_.data() + at_;
  at_ += n;
  return p;
}

void WireReader::fail() { throw std::runtime_error("transport: a message ended before its contents"); }

}  // namespace nodes
