// MPI session and transport; see mpi_transport.hpp.
#include "mpi/mpi_transport.hpp"

#include <climits>
#include <cstdlib>
#include <stdexcept>

namespace vmpi {
namespace {

// One line for a failed MPI call.
void check(int code, const char* call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(std::string("MPI: ") + call + " failed: " + std::string(text, static_cast<std::size_t>(length)));
}

}  // namespace

bool launched_by_mpi() {
  for (const char* variable : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"})
    if (std::getenv(variable) != nullptr) return true;
  return false;
}

// MPI_THREAD_SERIALIZED: during the run the MPI calls come from the bridge,
// a fiber on one of the runtime's threads, which is not the main thread, so
// FUNNELED is not enough; the main thread waits for the runtime meanwhile,
// and never two threads call at once, so MULTIPLE is not needed.
MpiSession::MpiSession(int& argc, char**& argv) {
  int provided = MPI_THREAD_SINGLE;
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
  if (provided < MPI_THREAD_SERIALIZED) {
    MPI_Finalize();
    throw std::runtime_error("MPI: this MPI library does not offer MPI_THREAD_SERIALIZED, which vmpray needs");
  }
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm host;
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &host) == MPI_SUCCESS) {
    MPI_Comm_size(host, &local_size_);
    MPI_Comm_free(&host);
  }
}

MpiSession::~MpiSession() { MPI_Finalize(); }

void MpiSession::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

// A communicator of its own, so that nothing else in the process can match
// the transport's messages.
MpiTransport::MpiTransport() {
  check(MPI_Comm_dup(MPI_COMM_WORLD, &comm_), "MPI_Comm_dup");
  MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN);
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

MpiTransport::~MpiTransport() {
  // Every rank ends with no send pending (the machine flushes); a rank that
  // ends early on a failure cancels what is left rather than hang.
  for (MPI_Request& request : requests_) {
    MPI_Cancel(&request);
    MPI_Request_free(&request);
  }
  MPI_Comm_free(&comm_);
}

void MpiTransport::post(int to, nodes::Tag tag, nodes::Bytes message) {
  if (message.size() > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error("MPI: a message of " + std::to_string(message.size()) +
                             " bytes is larger than one MPI message carries (2 GiB)");
  MPI_Request request;
  check(MPI_Isend(message.data(), static_cast<int>(message.size()), MPI_BYTE, to, static_cast<int>(tag), comm_,
                  &request),
        "MPI_Isend");
  requests_.push_back(request);
  buffers_.push_back(std::move(message));
}

// Open MPI moves messages only inside MPI calls (no asynchronous progress
// thread), so the bridge calls this often enough: after every packet it
// takes and at least every millisecond while idle. The message is there once
// MPI_Improbe finds it, so MPI_Mrecv of the probed size returns at once.
std::optional<nodes::Incoming> MpiTransport::poll(nodes::Tag tag) {
  int found = 0;
  MPI_Message message;
  MPI_Status status;
  check(MPI_Improbe(MPI_ANY_SOURCE, static_cast<int>(tag), comm_, &found, &message, &status), "MPI_Improbe");
  if (!found) return std::nullopt;
  int count = 0;
  check(MPI_Get_count(&status, MPI_BYTE, &count), "MPI_Get_count");
  nodes::Incoming incoming{status.MPI_SOURCE, nodes::Bytes(static_cast<std::size_t>(count))};
  check(MPI_Mrecv(incoming.bytes.data(), count, MPI_BYTE, &message, MPI_STATUS_IGNORE), "MPI_Mrecv");
  return incoming;
}

void MpiTransport::progress() {
  if (requests_.empty()) return;
  done_.resize(requests_.size());
  int count = 0;
  check(MPI_Testsome(static_cast<int>(requests_.size()), requests_.data(), &count, done_.data(), MPI_STATUSES_IGNORE),
        "MPI_Testsome");
  if (count <= 0) return;  // none complete (or MPI_UNDEFINED: none active)
  // Completed requests are MPI_REQUEST_NULL now: drop them with their bytes.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < requests_.size(); ++i) {
    if (requests_[i] == MPI_REQUEST_NULL) continue;
    if (kept != i) {  // a vector moved onto itself would free the bytes MPI is still sending
      requests_[kept] = requests_[i];
      buffers_[kept] = std::move(buffers_[i]);
    }
    ++kept;
  }
  requests_.resize(kept);
  buffers_.resize(kept);
}

}  // namespace vmpi
