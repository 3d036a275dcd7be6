#include "mpi_communicator.h"

// The C API only: Open MPI and MPICH would otherwise drag in their
// deprecated C++ bindings, which need a library of their own.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <unistd.h>

#include <climits>
#include <cstdint>
#include <cstdlib>

namespace pvr::comm {

namespace {

int countOf(std::size_t bytes) {
  if (bytes > std::size_t(INT_MAX))
    throw Error(ErrorCode::kUnsupported,
                "message of " + std::to_string(bytes) + " bytes exceeds MPI's 2 GiB count");
  return int(bytes);
}

void* sendPointer(std::span<const std::byte> data) {
  return const_cast<std::byte*>(data.data());  // MPI-3 takes const void*; keep it portable
}

class MpiCommunicator final : public Communicator {
 public:
  explicit MpiCommunicator(MPI_Comm comm) : comm_(comm) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void send(int to, int tag, std::span<const std::byte> data) override {
    MPI_Send(sendPointer(data), countOf(data.size()), MPI_BYTE, to, tag, comm_);
  }

  Bytes receive(int from, int tag) override {
    // Probe first: the receiver does not know the length of a sparse image.
    MPI_Status status;
    MPI_Probe(from, tag, comm_, &status);
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    Bytes data(static_cast<std::size_t>(count));
    MPI_Recv(data.data(), count, MPI_BYTE, from, tag, comm_, MPI_STATUS_IGNORE);
    return data;
  }

  Bytes sendReceive(int to, std::span<const std::byte> data, int from, int tag) override {
    MPI_Request request;
    MPI_Isend(sendPointer(data), countOf(data.size()), MPI_BYTE, to, tag, comm_, &request);
    Bytes received = receive(from, tag);
    MPI_Wait(&request, MPI_STATUS_IGNORE);
    return received;
  }

  std::vector<Bytes> exchange(std::span<const Outgoing> sends, std::span<const int> from,
                              int tag) override {
    std::vector<MPI_Request> requests(sends.size());
    for (std::size_t i = 0; i < sends.size(); ++i)
      MPI_Isend(sendPointer(sends[i].data), countOf(sends[i].data.size()), MPI_BYTE, sends[i].to,
                tag, comm_, &requests[i]);
    std::vector<Bytes> received;
    received.reserve(from.size());
    for (int f : from) received.push_back(receive(f, tag));
    MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
    return received;
  }

  void broadcast(Bytes& data, int root) override {
    std::uint64_t length = data.size();
    MPI_Bcast(&length, 1, MPI_UINT64_T, root, comm_);
    data.resize(std::size_t(length));
    MPI_Bcast(data.data(), countOf(data.size()), MPI_BYTE, root, comm_);
  }

  std::vector<Bytes> allGather(std::span<const std::byte> mine) override {
    const int count = countOf(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(size_)), offsets(static_cast<std::size_t>(size_));
    MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
    std::size_t total = 0;
    for (int r = 0; r < size_; ++r) {
      offsets[std::size_t(r)] = countOf(total);
      total += std::size_t(counts[std::size_t(r)]);
    }
    Bytes all(total);
    MPI_Allgatherv(sendPointer(mine), count, MPI_BYTE, all.data(), counts.data(), offsets.data(),
                   MPI_BYTE, comm_);
    std::vector<Bytes> out(static_cast<std::size_t>(size_));
    for (int r = 0; r < size_; ++r) {
      const auto begin = all.begin() + offsets[std::size_t(r)];
      out[std::size_t(r)].assign(begin, begin + counts[std::size_t(r)]);
    }
    return out;
  }

  void allReduceSum(std::span<std::uint64_t> values) override {
    MPI_Allreduce(MPI_IN_PLACE, values.data(), countOf(values.size()), MPI_UINT64_T, MPI_SUM, comm_);
  }

  void allReduceMax(std::span<double> values) override {
    MPI_Allreduce(MPI_IN_PLACE, values.data(), countOf(values.size()), MPI_DOUBLE, MPI_MAX, comm_);
  }

  void barrier() override { MPI_Barrier(comm_); }

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
};

// Waits for a non-blocking request: spins briefly (an action's next step
// usually follows at once), then sleeps between tests.
void waitPolitely(MPI_Request& request) {
  int done = 0;
  for (int spin = 0; spin < 2000 && !done; ++spin) MPI_Test(&request, &done, MPI_STATUS_IGNORE);
  while (!done) {
    ::usleep(500);
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
  }
}

// A command is its length, broadcast without blocking (the other ranks
// wait in MPI_Ibcast, and a non-blocking collective matches only another),
// then its bytes.
class MpiCommandChannel final : public CommandChannel {
 public:
  MpiCommandChannel() { MPI_Comm_dup(MPI_COMM_WORLD, &comm_); }
  ~MpiCommandChannel() override { MPI_Comm_free(&comm_); }

  void post(std::span<const std::byte> command) override {
    std::uint64_t length = command.size();
    MPI_Request request;
    MPI_Ibcast(&length, 1, MPI_UINT64_T, 0, comm_, &request);
    MPI_Wait(&request, MPI_STATUS_IGNORE);
    if (length) MPI_Bcast(sendPointer(command), countOf(command.size()), MPI_BYTE, 0, comm_);
  }

  Bytes await() override {
    std::uint64_t length = 0;
    MPI_Request request;
    MPI_Ibcast(&length, 1, MPI_UINT64_T, 0, comm_, &request);
    waitPolitely(request);
    Bytes command(length);
    if (length) MPI_Bcast(command.data(), countOf(command.size()), MPI_BYTE, 0, comm_);
    return command;
  }

  [[noreturn]] void abortJob(int status) override {
    MPI_Abort(MPI_COMM_WORLD, status);
    std::abort();  // MPI_Abort does not return; the compiler cannot know
  }

 private:
  MPI_Comm comm_;
};

}  // namespace

MpiEnvironment::MpiEnvironment(int* argc, char*** argv) {
  // Only the main thread calls MPI; render threads never do.
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  world_ = std::make_unique<MpiCommunicator>(MPI_COMM_WORLD);
  commands_ = std::make_unique<MpiCommandChannel>();
}

MpiEnvironment::~MpiEnvironment() {
  commands_.reset();
  world_.reset();
  MPI_Finalize();
}

Communicator& MpiEnvironment::world() { return *world_; }

CommandChannel& MpiEnvironment::commands() { return *commands_; }

}  // namespace pvr::comm
