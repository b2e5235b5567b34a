// The machine's Transport over MPI (Open MPI on Debian), for a machine split
// over OS processes and hosts, one rank per process.
//
// Thread level: MPI_THREAD_SERIALIZED. MPI_Init_thread and MPI_Finalize run
// on the main thread (MpiSession); during the run every other call comes
// from the rank's bridge process (nodes/ranks/bridge.hpp), a fiber on a
// runtime thread, never two threads at once. Only non-blocking calls are
// made (MPI_Isend, MPI_Improbe with MPI_Mrecv of the probed size,
// MPI_Testsome): a fiber blocked in MPI would stall its whole OS thread.
// Order: one communicator (a duplicate of MPI_COMM_WORLD), one tag per Tag;
// MPI keeps the messages between one pair of ranks on one communicator and
// tag in order, which is the order Transport promises. Why these choices:
// mpi_transport.cpp.
#pragma once

#include <mpi.h>

#include <string>
#include <vector>

#include "nodes/ranks/transport.hpp"

namespace vmpi {

// Whether this process was started by an MPI launcher (mpirun, mpiexec, or
// a PMIx/PMI-based one such as srun): the launcher's environment says so.
bool launched_by_mpi();

// MPI_Init_thread (SERIALIZED) in the constructor, MPI_Finalize in the
// destructor. Throws std::runtime_error if MPI cannot give that level.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  int ranks_on_this_host() const { return local_size_; }
  // Ends every rank of the job: for a failure the wire could not report.
  [[noreturn]] static void abort(int code);

 private:
  int rank_ = 0;
  int size_ = 1;
  int local_size_ = 1;
};

class MpiTransport final : public nodes::Transport {
 public:
  MpiTransport();  // after MpiSession
  ~MpiTransport() override;
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void post(int to, nodes::Tag tag, nodes::Bytes message) override;
  std::optional<nodes::Incoming> poll(nodes::Tag tag) override;
  void progress() override;
  std::size_t pending() const override { return requests_.size(); }

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  int size_ = 1;
  std::vector<MPI_Request> requests_;  // sends not yet complete
  std::vector<nodes::Bytes> buffers_;  // their bytes, same index
  std::vector<int> done_;              // Testsome's scratch
};

}  // namespace vmpi
