// Runtime, par, sleep_for, yield: threads, placement, process lifetime, failures.
#include "csp/runtime.hpp"

#include <boost/fiber/fiber.hpp>
#include <boost/fiber/operations.hpp>
#include <algorithm>
#include <barrier>
#include <ctime>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <new>
#include <stdexcept>
#include <thread>
#include <utility>

#include "csp/detail/process.hpp"
#include "csp/detail/stack.hpp"
#include "csp/detail/wait.hpp"
#include "csp/errors.hpp"

namespace csp {

namespace detail {

namespace {

struct Failure {
  std::string process;
  std::exception_ptr error;
};

// One failure: rethrown as is; several: ProcessesFailed naming the first
// few and counting the rest.
[[noreturn]] void rethrow_failures(const std::vector<Failure>& failures) {
  constexpr std::size_t named = 4;
  if (failures.size() == 1) std::rethrow_exception(failures.front().error);
  std::string text = "process '" + failures.front().process + "' failed: " + message_of(failures.front().error) +
                     "; and " + std::to_string(failures.size() - 1) + " more:";
  for (std::size_t i = 1; i < std::min(failures.size(), named); ++i) {
    text += " process '" + failures[i].process + "': " + message_of(failures[i].error) + ";";
  }
  text.pop_back();
  if (failures.size() > named) text += "; ...";
  const bool out_of_memory = std::any_of(failures.begin(), failures.end(), [](const Failure& f) {
    try {
      std::rethrow_exception(f.error);
    } catch (const std::bad_alloc&) {
      return true;
    } catch (...) {
      return false;
    }
  });
  throw ProcessesFailed(text, out_of_memory);
}

// The failures of a group of processes (a Runtime's, or a PAR's children),
// in the order they ended; the first is the one reported. Its owner guards
// it with its own lock. note() runs where an exception would end the
// program (a fiber's end, a runtime thread's loop): with no memory left to
// record a failure, it counts it as lost instead.
class Failures {
 public:
  void note(const std::string& process, std::exception_ptr error) noexcept {
    try {
      recorded_.push_back({process, std::move(error)});
    } catch (...) {
      ++lost_;
    }
  }
  bool any() const { return !recorded_.empty() || lost_ > 0; }
  const std::vector<Failure>& recorded() const { return recorded_; }
  std::size_t lost() const { return lost_; }

  // After the group has ended: the recorded failures as rethrow_failures
  // reports them; if none was recorded but `lost` were (this list's, plus
  // any the caller adds), ProcessesFailed "N" + why_lost, out of memory.
  void rethrow_if_failed(const std::string& why_lost, std::size_t also_lost = 0) const {
    if (!recorded_.empty()) rethrow_failures(recorded_);
    if (const std::size_t lost = lost_ + also_lost; lost > 0)
      throw ProcessesFailed(std::to_string(lost) + why_lost, true);
  }

 private:
  std::vector<Failure> recorded_;
  std::size_t lost_ = 0;
};

// What ProcessNotStarted says of one process.
std::string could_not_start(const std::string& process, const std::exception_ptr& error) {
  return "process '" + process + "' could not start: " + message_of(error);
}

enum class Ending { normal, poisoned, deadlock, failed };

Ending run_body(const std::function<void()>& body, std::exception_ptr& error) {
  try {
    body();
    return Ending::normal;
  } catch (const Poisoned&) {
    error = std::current_exception();
    return Ending::poisoned;
  } catch (const DeadlockUnwind&) {
    return Ending::deadlock;
  } catch (...) {
    error = std::current_exception();
    return Ending::failed;
  }
}

double seconds_of(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

// The calling thread's CPU time so far (0 where the OS cannot tell).
double thread_cpu_seconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Binds the calling fiber to its process record (or unbinds it with null).
void bind_fiber(Process* p) {
  if (!thread_scheduler()) return;
  if (auto* props = boost::fibers::context::active()->get_properties()) {
    static_cast<ProcessProps*>(props)->process = p;
  }
}

boost::fibers::fiber start_fiber(std::size_t stack_size, std::function<void()> fn) {
  return boost::fibers::fiber(std::allocator_arg, ProcessStack(stack_size), std::move(fn));
}

}  // namespace

// Holds the runtime threads until every one of them exists and has set up
// its scheduler, so that a thread the system cannot create, or one left
// without memory for its scheduler, abandons the run before any process
// starts. The threads set up one at a time, once all exist, so that what
// one finds of the memory left is not taken by another meanwhile.
class StartGate {
 public:
  explicit StartGate(unsigned threads) : setting_up_(threads) {}

  // The creator: every thread exists.
  void all_created() { settle(State::setting_up); }
  // The creator: a thread could not be created.
  void abandon() { settle(State::abandoned); }

  // A runtime thread: runs set_up() (which may throw) in its turn, then
  // waits for the verdict. True: run.
  template <class SetUp>
  bool set_up_and_wait(unsigned thread, SetUp set_up) {
    std::unique_lock<std::mutex> lk(mutex_);
    changed_.wait(lk, [this] { return state_ != State::creating; });
    if (state_ == State::abandoned) return false;
    try {
      set_up();
    } catch (...) {
      if (!failure_) {
        failure_ = std::current_exception();
        failed_thread_ = thread;
      }
    }
    if (--setting_up_ == 0) changed_.notify_all();
    changed_.wait(lk, [this] { return state_ == State::go || state_ == State::abandoned; });
    return state_ == State::go;
  }

  // The creator, after all_created(): waits for the set-ups, then lets the
  // threads run if all succeeded. Returns the first failure, if any.
  std::exception_ptr open_when_set_up(unsigned& failed_thread) {
    std::exception_ptr failure;
    {
      std::unique_lock<std::mutex> lk(mutex_);
      changed_.wait(lk, [this] { return setting_up_ == 0; });
      state_ = failure_ ? State::abandoned : State::go;
      failure = failure_;
      failed_thread = failed_thread_;
    }
    changed_.notify_all();
    return failure;
  }

 private:
  enum class State { creating, setting_up, go, abandoned };

  void settle(State s) {
    {
      std::lock_guard<std::mutex> lk(mutex_);
      state_ = s;
    }
    changed_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  unsigned setting_up_;
  std::exception_ptr failure_;
  unsigned failed_thread_ = 0;
  State state_ = State::creating;
};

// A process placed on a thread but not started yet.
struct Spawn {
  std::shared_ptr<Process> process;
  std::function<void()> body;
};

// One runtime thread. Its main fiber waits on the inbox for new processes
// and for the stop signal sent when the last process of the run has ended.
struct Worker {
  Spinlock lock;
  std::vector<Spawn> inbox;  // guarded by lock
  Waiter* idle = nullptr;    // guarded by lock: the main fiber, parked
  bool stop = false;         // guarded by lock

  // Lock held: wakes the parked main fiber, if any.
  void wake_locked() {
    if (idle && try_claim(*idle)) complete(*idle, WaitState::data, 0);
    idle = nullptr;
  }
};

}  // namespace detail

using detail::Process;
using detail::seconds_of;
using detail::Spawn;
using detail::SpinlockLock;
using detail::thread_cpu_seconds;
using detail::Worker;

struct Runtime::Impl {
  // More than Boost allocates to start fibers on a thread (its dispatcher's
  // stack is 128 KB).
  static constexpr std::size_t boost_thread_set_up_bytes = 1 << 20;

  explicit Impl(RuntimeOptions o)
      : options(with_thread_count(std::move(o))), tracker(options.threads, [this] { stop_all(); }) {
    for (unsigned i = 0; i < options.threads; ++i) workers.push_back(std::make_unique<Worker>());
    use.resize(options.threads);
    times.resize(options.threads);
  }

  static RuntimeOptions with_thread_count(RuntimeOptions o) {
    if (o.threads == 0) o.threads = std::max(1u, std::thread::hardware_concurrency());
    return o;
  }

  // Counts the process alive and hands it to its thread; if either fails,
  // neither is done.
  void post(Spawn s) {
    Worker& w = *workers[s.process->thread];
    detail::ChannelLock lk(w.lock);
    if (w.inbox.size() == w.inbox.capacity()) w.inbox.reserve(2 * w.inbox.size() + 1);
    tracker.add(*s.process);
    w.inbox.push_back(std::move(s));  // into the room made above: cannot throw
    w.wake_locked();
  }

  void stop_all() {
    for (auto& w : workers) {
      detail::ChannelLock lk(w->lock);
      w->stop = true;
      w->wake_locked();
    }
  }

  void worker_main(unsigned index, detail::StartGate& gate, std::barrier<>& finished);
  void set_up_thread(unsigned index);
  void serve(unsigned index);
  void launch_all(std::vector<Spawn>& batch, std::vector<boost::fibers::fiber>& fibers);
  boost::fibers::fiber launch(Spawn s);
  void not_started(Process& p, std::exception_ptr error);
  void run_process(Process& p, const std::function<void()>& body);

  RuntimeOptions options;
  std::vector<std::unique_ptr<Worker>> workers;
  std::vector<ThreadUse> use;  // element i written by thread i only, read after the join
  // Element i gathered by thread i's FifoScheduler, which may outlive
  // worker_main; serve() starts it and copies it into use[i].
  std::vector<ThreadTimes> times;
  detail::Tracker tracker;
  std::mutex failures_mutex;
  detail::Failures failures;   // guarded by failures_mutex: processes that threw
  detail::Failures unstarted;  // guarded by failures_mutex: processes that could not start
  bool started = false;
  bool finished = false;  // every thread has exited: nothing can start any more
};

// Installs this thread's scheduler and gives its main fiber and Boost's
// dispatcher their properties now, while a failure can still be reported.
// Boost makes the thread's fiber context, scheduler and dispatcher stack
// where std::bad_alloc ends the program, so room for them is first tried.
void Runtime::Impl::set_up_thread(unsigned index) {
  if (!detail::address_space_free(boost_thread_set_up_bytes)) throw std::bad_alloc();
  const std::chrono::microseconds spin = options.shared_cores
                                              ? std::chrono::microseconds{0}
                                              : idle_spin(options.threads, std::thread::hardware_concurrency());
  std::unique_ptr<Scheduler> owned(options.scheduler ? options.scheduler(index)
                                                     : new FifoScheduler(&times[index], spin));
  Scheduler* algo = owned.get();
  boost::fibers::context* main = boost::fibers::context::active();
  algo->make_room_for_fiber();  // for the dispatcher, which set_algo makes ready
  main->get_scheduler()->set_algo(boost::fibers::algo::algorithm::ptr_t(owned.release()));
  detail::set_thread_scheduler(main->get_scheduler(), algo);
  algo->make_room_for_fiber();  // for the main fiber's, made next
  main->set_properties(algo->new_properties(main));
}

void Runtime::Impl::worker_main(unsigned index, detail::StartGate& gate, std::barrier<>& finished) {
  if (gate.set_up_and_wait(index, [this, index] { set_up_thread(index); })) {
    serve(index);
    // A fiber of another thread may still be inside this thread's scheduler,
    // waking it; the scheduler dies with the thread, so wait for every
    // thread to finish its fibers first, and for any wake from outside the
    // runtime (a shutdown from another thread) to be through notify().
    finished.arrive_and_wait();
    while (detail::remote_wakes_in_flight.load(std::memory_order_seq_cst) != 0) std::this_thread::yield();
  }
  detail::set_thread_scheduler(nullptr, nullptr);
  detail::release_properties_reserve();
}

// Starts the processes posted to this thread until told to stop, then
// waits for them to end.
void Runtime::Impl::serve(unsigned index) {
  const auto started = std::chrono::steady_clock::now();
  const double cpu_started = thread_cpu_seconds();
  times[index].start(started);
  detail::remote_wakes_here = 0;
  detail::sleepers_woken_here = 0;
  std::vector<boost::fibers::fiber> fibers;
  Worker& w = *workers[index];
  for (bool stop = false; !stop;) {
    SpinlockLock lk(w.lock);
    while (w.inbox.empty() && !w.stop) {
      detail::Waiter idle;
      w.idle = &idle;
      detail::park(idle, lk);  // the main fiber is no process: never counted
      lk.lock();
    }
    std::vector<Spawn> batch = std::move(w.inbox);
    w.inbox.clear();
    stop = w.stop;
    lk.unlock();
    launch_all(batch, fibers);
  }
  for (boost::fibers::fiber& f : fibers) f.join();
  const auto ended = std::chrono::steady_clock::now();
  ThreadUse& u = use[index];
  u.cpu_seconds = thread_cpu_seconds() - cpu_started;
  u.seconds = seconds_of(ended - started);
  u.remote_wakes = detail::remote_wakes_here;
  u.sleepers_woken = detail::sleepers_woken_here;
  if (options.scheduler) return;  // another scheduler keeps no accounts
  ThreadTimes& t = times[index];
  t.close(ended);
  u.running_seconds = seconds_of(t.running);
  u.spinning_seconds = seconds_of(t.spinning);
  u.sleeping_seconds = seconds_of(t.sleeping);
  u.idle_seconds = seconds_of(t.spinning + t.sleeping);
  u.waits = t.waits;
  u.sleeps = t.sleeps;
}

// A process that cannot start (no memory for its stack) is recorded and no
// longer counted alive, so the run still ends: whoever waits for it is
// unwound as in a deadlock, and run() reports the failed start instead.
void Runtime::Impl::launch_all(std::vector<Spawn>& batch, std::vector<boost::fibers::fiber>& fibers) {
  for (Spawn& s : batch) {
    const std::shared_ptr<Process> p = s.process;
    try {
      // Room first: a joinable fiber must not be lost to a failed push_back.
      if (fibers.size() == fibers.capacity()) fibers.reserve(2 * fibers.size() + batch.size());
      fibers.push_back(launch(std::move(s)));
    } catch (...) {
      not_started(*p, std::current_exception());
    }
  }
}

void Runtime::Impl::not_started(Process& p, std::exception_ptr error) {
  {
    std::lock_guard<std::mutex> lk(failures_mutex);
    unstarted.note(p.name, std::move(error));
  }
  tracker.remove(p);
}

boost::fibers::fiber Runtime::Impl::launch(Spawn s) {
  const std::size_t stack_size = s.process->stack_size;
  detail::thread_algorithm()->make_room_for_fiber();
  return detail::start_fiber(stack_size, [this, s = std::move(s)] { run_process(*s.process, s.body); });
}

void Runtime::Impl::run_process(Process& p, const std::function<void()>& body) {
  detail::bind_fiber(&p);
  std::exception_ptr error;
  if (detail::run_body(body, error) == detail::Ending::failed) {
    {
      std::lock_guard<std::mutex> lk(failures_mutex);
      failures.note(p.name, error);
    }
    if (options.on_failure) try {
        options.on_failure(p.name, error);
      } catch (...) {
      }
  }
  detail::bind_fiber(nullptr);
  tracker.remove(p);
}

Runtime::Runtime(unsigned threads) : Runtime(RuntimeOptions{threads, RuntimeOptions{}.stack_size, {}, false, {}}) {}
Runtime::Runtime(RuntimeOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  detail::prepare_fences();
}
Runtime::~Runtime() = default;

unsigned Runtime::threads() const { return impl_->options.threads; }

std::vector<ThreadUse> Runtime::thread_use() const { return impl_->use; }

void Runtime::spawn(std::string name, unsigned thread, std::function<void()> body, Priority priority) {
  if (impl_->finished) throw std::logic_error("Runtime::spawn: the run has ended, '" + name + "' cannot start");
  auto p = std::make_shared<Process>();
  p->name = std::move(name);
  p->thread = thread % threads();
  p->priority = priority;
  p->stack_size = impl_->options.stack_size;
  impl_->post(Spawn{p, std::move(body)});
}

void Runtime::run() {
  if (impl_->started) throw std::logic_error("Runtime::run: a Runtime runs once");
  impl_->started = true;
  if (impl_->tracker.alive() == 0) {
    impl_->finished = true;
    return;
  }
  const unsigned count = impl_->options.threads;
  std::vector<std::thread> threads;
  detail::StartGate gate(count);
  std::barrier<> finished(count);
  const auto give_up = [&](const std::string& what, std::size_t thread, const std::exception_ptr& why) {
    for (std::thread& t : threads) t.join();
    impl_->finished = true;
    throw ThreadNotStarted("csp: could not " + what + " runtime thread " + std::to_string(thread + 1) + " of " +
                             std::to_string(count) + ", so no process ran: " + message_of(why));
  };
  try {
    threads.reserve(count);
    for (unsigned i = 0; i < count; ++i)
      threads.emplace_back([this, i, &gate, &finished] { impl_->worker_main(i, gate, finished); });
  } catch (...) {
    gate.abandon();
    give_up("start", threads.size(), std::current_exception());
  }
  gate.all_created();
  unsigned failed_thread = 0;
  if (const std::exception_ptr failure = gate.open_when_set_up(failed_thread))
    give_up("set up", failed_thread, failure);
  for (std::thread& t : threads) t.join();
  impl_->finished = true;

  // A process that could not start is the cause of what followed.
  const detail::Failures& unstarted = impl_->unstarted;
  if (!unstarted.recorded().empty()) {
    const auto& first = unstarted.recorded().front();
    const std::size_t more = unstarted.recorded().size() - 1 + unstarted.lost();
    std::string text = detail::could_not_start(first.process, first.error);
    if (more > 0) text += " (and " + std::to_string(more) + " more processes)";
    throw ProcessNotStarted(text);
  }
  if (unstarted.any())
    throw ProcessNotStarted(std::to_string(unstarted.lost()) +
                            " processes could not start, and no memory was left to record which");
  // Processes left waiting on one that failed deadlock: the failure is the cause.
  impl_->failures.rethrow_if_failed(" processes failed, and no memory was left to record why");
  if (impl_->tracker.aborting()) throw Deadlock(impl_->tracker.deadlock_dump());
}

// The state a PAR shares with its children, guarded by lock.
struct ParGroup {
  detail::Spinlock lock;
  std::size_t remaining = 0;
  detail::Waiter* parent = nullptr;  // the parent, while parked until remaining == 0
  detail::Failures failures;         // children that threw
  detail::Failures poisons;          // children ended by poison: the first is rethrown if nothing else failed
  bool deadlock = false;
};

namespace {

void run_child(ParGroup& g, Process& child, const std::function<void()>& body) {
  detail::bind_fiber(&child);
  std::exception_ptr error;
  const detail::Ending e = detail::run_body(body, error);
  detail::bind_fiber(nullptr);
  {
    detail::ChannelLock lk(g.lock);
    if (e == detail::Ending::failed) g.failures.note(child.name, error);
    if (e == detail::Ending::poisoned) g.poisons.note(child.name, error);
    g.deadlock |= e == detail::Ending::deadlock;
    // Wake the parent before ending, so it is never counted blocked alone.
    if (--g.remaining == 0 && g.parent && detail::try_claim(*g.parent)) {
      detail::complete(*g.parent, detail::WaitState::data, 0);
    }
  }
  child.tracker->remove(child);
}

std::string child_name(const Process& parent, std::size_t i) { return parent.name + "." + std::to_string(i); }

}  // namespace

void par(std::vector<std::function<void()>> processes) {
  if (!detail::thread_scheduler()) {
    // A plain thread: run the PAR as a process, so that a deadlock among the
    // children is found and thrown rather than waited on forever.
    Runtime runtime(1);
    runtime.spawn("par", 0, [&processes] { par(std::move(processes)); });
    runtime.run();
    return;
  }
  Process* parent = detail::current_process();
  if (!parent) throw std::logic_error("csp::par: called from a fiber of a runtime thread that is no process");
  ParGroup g;
  g.remaining = processes.size();
  std::vector<boost::fibers::fiber> fibers;
  fibers.reserve(processes.size());
  std::exception_ptr not_started;  // why a child could not start (none after it did)
  std::size_t not_started_child = 0;
  for (std::size_t i = 0; i < processes.size(); ++i) {
    std::shared_ptr<Process> child;
    bool counted = false;
    try {
      child = std::make_shared<Process>();
      child->name = child_name(*parent, i);
      child->thread = parent->thread;
      child->priority = parent->priority;
      child->stack_size = parent->stack_size;
      parent->tracker->add(*child);
      counted = true;
      detail::thread_algorithm()->make_room_for_fiber();
      fibers.push_back(detail::start_fiber(parent->stack_size, [&g, child, body = std::move(processes[i])] {
        run_child(g, *child, body);
      }));
    } catch (...) {
      // The children started go on, and are waited for below: they use g.
      not_started = std::current_exception();
      not_started_child = i;
      if (counted) parent->tracker->remove(*child);
      detail::ChannelLock lk(g.lock);
      g.remaining -= processes.size() - i;
      break;
    }
  }
  // The parent parks, counted as blocked, until its children have ended.
  {
    SpinlockLock lk(g.lock);
    while (g.remaining > 0) {
      detail::Waiter w;
      w.op = "in PAR, waiting for its children";
      w.abortable = false;  // the children unwind first and then wake it
      g.parent = &w;
      detail::park(w, lk);
      lk.lock();
      g.parent = nullptr;
    }
  }
  for (boost::fibers::fiber& f : fibers) f.join();
  if (not_started)  // the cause of any deadlock below
    throw ProcessNotStarted(detail::could_not_start(child_name(*parent, not_started_child), not_started));
  if (g.deadlock) detail::unwind_deadlock();
  // A poison lost for want of memory counts as a failure, as out of memory.
  g.failures.rethrow_if_failed(" processes of a PAR failed, and no memory was left to record why", g.poisons.lost());
  if (!g.poisons.recorded().empty()) std::rethrow_exception(g.poisons.recorded().front().error);
}

void sleep_for(std::chrono::steady_clock::duration d) { boost::this_fiber::sleep_for(d); }

bool yield_requested() {
  const Scheduler* s = detail::thread_algorithm();
  return s && s->yield_requested();
}

namespace {
// Yields with `mark` set in the caller's properties, for the scheduler to
// place it by (FifoScheduler::awakened clears it).
void yield_marked(bool ProcessProps::*mark) {
  if (detail::thread_scheduler())
    if (auto* props = boost::fibers::context::active()->get_properties())
      static_cast<ProcessProps*>(props)->*mark = true;
  boost::this_fiber::yield();
}
}  // namespace

void yield() { yield_marked(&ProcessProps::yielded); }

void yield_to_urgent() { yield_marked(&ProcessProps::ahead); }

bool yield_to_all() {
  const Scheduler* s = detail::thread_algorithm();
  if (!s || !s->others_ready()) return false;
  if (auto* props = boost::fibers::context::active()->get_properties())
    static_cast<ProcessProps*>(props)->behind_all = true;
  boost::this_fiber::yield();
  return true;
}

const std::string& current_process_name() {
  static const std::string none;
  const Process* p = detail::current_process();
  return p ? p->name : none;
}

}  // namespace csp
