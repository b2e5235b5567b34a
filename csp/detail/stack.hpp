// Process stacks: each has a guard page below it, which the kernel refuses
// to touch, so a process that runs off the end of its stack faults at once
// instead of writing over another process's memory.
//
// Invariant: a guarded stack is two memory mappings (its guard and the
// rest), and the kernel allows a process vm.max_map_count of them (65 530
// by default; a 4096-node machine runs 16 389 processes, and 77 828 under
// virtual time, where every link is a process too). So at most a quarter
// of that many guarded stacks live at once in the whole program;
// beyond, and wherever a guard cannot be made, a stack comes without one.
// The allocator tells the two apart by size when it frees them. A freed
// guarded stack is kept for the next process that needs one of its size
// (stack.cpp says why), and counts as alive meanwhile.
#pragma once

#include <cstddef>

#include <boost/context/stack_context.hpp>

namespace csp::detail {

class ProcessStack {
 public:
  explicit ProcessStack(std::size_t size);  // usable bytes, rounded up to whole pages

  boost::context::stack_context allocate();
  void deallocate(boost::context::stack_context& sctx) noexcept;

  // Guarded stacks in the program now (in use or kept), and the most there may be.
  static std::size_t guarded_alive();
  static std::size_t guarded_limit();

 private:
  std::size_t size_;
  std::size_t page_;
};

// Whether `bytes` of address space could be mapped now (ulimit -v leaves
// room for them): maps and unmaps them, leaving the C library's allocator
// as it was (a freed malloc block that large would raise its mmap threshold).
bool address_space_free(std::size_t bytes);

}  // namespace csp::detail
