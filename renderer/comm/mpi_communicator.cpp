#include "mpi_communicator.h"

// The C API only: Open MPI and MPICH would otherwise drag in their
// deprecated C++ bindings, which need a library of their own.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <string>

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

// Every call that may block on another rank marks the rank as waiting, so
// that its watchdog blames the rank waited for, not this one.
using Waiting = LivenessScope;
constexpr auto kWaits = LivenessScope::Kind::kWaiting;

// Waits until `done()` says so: tests a few hundred times (the answer
// usually follows at once), then sleeps between tests, 50 us doubling to
// 500 us. MPI's own waits spin on their core for the whole wait.
template <typename Done>
void waitPolitely(Done&& done) {
  for (int spin = 0; spin < 200; ++spin)
    if (done()) return;
  for (useconds_t pause = 50; !done(); pause = std::min<useconds_t>(2 * pause, 500)) ::usleep(pause);
}

void waitPolitely(MPI_Request& request) {
  waitPolitely([&] {
    int done = 0;
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    return done != 0;
  });
}

// Whether this host runs more of the job's ranks than it has cores (8 on
// 2 here). Then a rank that waits in MPI's spinning calls takes a core
// from a rank still rendering: perf counted 0.7-1.3 CPU s of a 2048^3
// first frame's 8 ranks in MPI's waits. Collective over MPI_COMM_WORLD.
bool ranksOutnumberCores() {
  MPI_Comm host;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &host);
  int ranksHere = 1;
  MPI_Comm_size(host, &ranksHere);
  MPI_Comm_free(&host);
  const long cores = ::sysconf(_SC_NPROCESSORS_ONLN);
  return cores > 0 && ranksHere > cores;
}

class MpiCommunicator final : public Communicator {
 public:
  // polite: wait by testing and sleeping (waitPolitely), not in MPI's
  // spinning waits (ranksOutnumberCores).
  MpiCommunicator(MPI_Comm comm, Liveness* liveness, bool polite)
      : comm_(comm), liveness_(liveness), polite_(polite) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void send(int to, int tag, std::span<const std::byte> data) override {
    const Waiting waiting(liveness_, kWaits);
    MPI_Request request;
    MPI_Isend(sendPointer(data), countOf(data.size()), MPI_BYTE, to, tag, comm_, &request);
    wait(request);
  }

  Bytes receive(int from, int tag) override {
    const Waiting waiting(liveness_, kWaits);
    return receiveWaiting(from, tag);
  }

  Bytes sendReceive(int to, std::span<const std::byte> data, int from, int tag) override {
    const Waiting waiting(liveness_, kWaits);
    MPI_Request request;
    MPI_Isend(sendPointer(data), countOf(data.size()), MPI_BYTE, to, tag, comm_, &request);
    Bytes received = receiveWaiting(from, tag);
    wait(request);
    return received;
  }

  std::vector<Bytes> exchange(std::span<const Outgoing> sends, std::span<const int> from,
                              int tag) override {
    const Waiting waiting(liveness_, kWaits);
    std::vector<MPI_Request> requests(sends.size());
    for (std::size_t i = 0; i < sends.size(); ++i)
      MPI_Isend(sendPointer(sends[i].data), countOf(sends[i].data.size()), MPI_BYTE, sends[i].to,
                tag, comm_, &requests[i]);
    std::vector<Bytes> received;
    received.reserve(from.size());
    for (int f : from) received.push_back(receiveWaiting(f, tag));
    for (MPI_Request& request : requests) wait(request);
    return received;
  }

  void broadcast(Bytes& data, int root) override {
    const Waiting waiting(liveness_, kWaits);
    std::uint64_t length = data.size();
    MPI_Request request;
    MPI_Ibcast(&length, 1, MPI_UINT64_T, root, comm_, &request);
    wait(request);
    data.resize(std::size_t(length));
    MPI_Ibcast(data.data(), countOf(data.size()), MPI_BYTE, root, comm_, &request);
    wait(request);
  }

  std::vector<Bytes> allGather(std::span<const std::byte> mine) override {
    const Waiting waiting(liveness_, kWaits);
    const int count = countOf(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(size_)), offsets(static_cast<std::size_t>(size_));
    MPI_Request request;
    MPI_Iallgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_, &request);
    wait(request);
    std::size_t total = 0;
    for (int r = 0; r < size_; ++r) {
      offsets[std::size_t(r)] = countOf(total);
      total += std::size_t(counts[std::size_t(r)]);
    }
    Bytes all(total);
    MPI_Iallgatherv(sendPointer(mine), count, MPI_BYTE, all.data(), counts.data(), offsets.data(),
                    MPI_BYTE, comm_, &request);
    wait(request);
    std::vector<Bytes> out(static_cast<std::size_t>(size_));
    for (int r = 0; r < size_; ++r) {
      const auto begin = all.begin() + offsets[std::size_t(r)];
      out[std::size_t(r)].assign(begin, begin + counts[std::size_t(r)]);
    }
    return out;
  }

  void allReduceSum(std::span<std::uint64_t> values) override {
    const Waiting waiting(liveness_, kWaits);
    MPI_Request request;
    MPI_Iallreduce(MPI_IN_PLACE, values.data(), countOf(values.size()), MPI_UINT64_T, MPI_SUM, comm_, &request);
    wait(request);
  }

  void allReduceMax(std::span<double> values) override {
    const Waiting waiting(liveness_, kWaits);
    MPI_Request request;
    MPI_Iallreduce(MPI_IN_PLACE, values.data(), countOf(values.size()), MPI_DOUBLE, MPI_MAX, comm_, &request);
    wait(request);
  }

  void barrier() override {
    const Waiting waiting(liveness_, kWaits);
    MPI_Request request;
    MPI_Ibarrier(comm_, &request);
    wait(request);
  }

 private:
  void wait(MPI_Request& request) const {
    if (polite_) waitPolitely(request);
    else MPI_Wait(&request, MPI_STATUS_IGNORE);
  }

  // Probe first: the receiver does not know the length of a sparse image.
  // A matched probe (MPI_Mprobe), so that no other receive takes the message
  // between the probe and the receive.
  Bytes receiveWaiting(int from, int tag) const {
    MPI_Message message;
    MPI_Status status;
    if (polite_) {
      waitPolitely([&] {
        int found = 0;
        MPI_Improbe(from, tag, comm_, &found, &message, &status);
        return found != 0;
      });
    } else {
      MPI_Mprobe(from, tag, comm_, &message, &status);
    }
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    Bytes data(static_cast<std::size_t>(count));
    MPI_Mrecv(data.data(), count, MPI_BYTE, &message, MPI_STATUS_IGNORE);
    return data;
  }

  MPI_Comm comm_;
  Liveness* liveness_;
  bool polite_;
  int rank_ = 0, size_ = 1;
};

// A command is its length, broadcast without blocking (the other ranks
// wait in MPI_Ibcast, and a non-blocking collective matches only another),
// then its bytes.
class MpiCommandChannel final : public CommandChannel {
 public:
  explicit MpiCommandChannel(Liveness* liveness) : liveness_(liveness) { MPI_Comm_dup(MPI_COMM_WORLD, &comm_); }
  ~MpiCommandChannel() override { MPI_Comm_free(&comm_); }

  void post(std::span<const std::byte> command) override {
    const Waiting waiting(liveness_, kWaits);
    std::uint64_t length = command.size();
    MPI_Request request;
    MPI_Ibcast(&length, 1, MPI_UINT64_T, 0, comm_, &request);
    MPI_Wait(&request, MPI_STATUS_IGNORE);
    if (length) MPI_Bcast(sendPointer(command), countOf(command.size()), MPI_BYTE, 0, comm_);
  }

  Bytes await() override {
    const Waiting waiting(liveness_, kWaits);
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
  Liveness* liveness_;
};

// Sends are MPI_Isend of a copy kept until MPI says it is done (a stopped
// receiver leaves them pending; they are few and tiny); receiving is
// MPI_Iprobe, then MPI_Recv of what the probe found.
class MpiWatchChannel final : public WatchChannel {
 public:
  MpiWatchChannel() {
    MPI_Comm_dup(MPI_COMM_WORLD, &comm_);
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }
  ~MpiWatchChannel() override {
    for (auto& s : sending_) MPI_Request_free(&s.request);
    MPI_Comm_free(&comm_);
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void post(int to, std::span<const std::byte> message) override {
    reap();
    sending_.push_back({Bytes(message.begin(), message.end()), MPI_REQUEST_NULL});
    Sending& s = sending_.back();
    MPI_Isend(s.bytes.data(), countOf(s.bytes.size()), MPI_BYTE, to, kTag, comm_, &s.request);
  }

  std::optional<std::pair<int, Bytes>> take() override {
    reap();
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kTag, comm_, &arrived, &status);
    if (!arrived) return std::nullopt;
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    Bytes bytes(static_cast<std::size_t>(count));
    MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, kTag, comm_, MPI_STATUS_IGNORE);
    return std::pair{status.MPI_SOURCE, std::move(bytes)};
  }

 private:
  static constexpr int kTag = 1;
  struct Sending {
    Bytes bytes;
    MPI_Request request;
  };
  // Drops the sends MPI has finished with, oldest first.
  void reap() {
    while (!sending_.empty()) {
      int done = 0;
      MPI_Test(&sending_.front().request, &done, MPI_STATUS_IGNORE);
      if (!done) return;
      sending_.pop_front();
    }
  }

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  std::deque<Sending> sending_;
};

// A job whose ranks all run on this host (Open MPI's launcher says so
// before MPI_Init: OMPI_COMM_WORLD_LOCAL_SIZE == OMPI_COMM_WORLD_SIZE)
// talks through shared memory, which the ob1 PML carries (the vader BTL).
// Naming it, unless the user or the launcher named a PML, spares MPI_Init
// opening and probing the network PMLs (cm and its MTLs: PSM2, OFI):
// 0.61 -> 0.42 s of every rank's start for 8 ranks on a 2-core host,
// where the cores mostly wait. Other launchers set no such variables.
void preferSharedMemoryOnOneHost() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  if (!size || !local || std::string(size) != local || std::getenv("OMPI_MCA_pml")) return;
  ::setenv("OMPI_MCA_pml", "ob1", 0);
}

}  // namespace

MpiEnvironment::MpiEnvironment(int* argc, char*** argv, Threads threads) {
  preferSharedMemoryOnOneHost();
  // kMainOnly: only the main thread calls MPI; render threads never do.
  // kWatched: a watch thread calls MPI beside the main thread.
  const int wanted = threads == Threads::kWatched ? MPI_THREAD_MULTIPLE : MPI_THREAD_FUNNELED;
  int provided = 0;
  MPI_Init_thread(argc, argv, wanted, &provided);
  if (provided < wanted) {
    MPI_Finalize();
    throw Error(ErrorCode::kUnsupported,
                "this MPI library gives thread level " + std::to_string(provided) + ", below " +
                    (threads == Threads::kWatched ? std::string("MPI_THREAD_MULTIPLE, which pvr-node --server needs "
                                                               "for its watch thread (Open MPI: built with "
                                                               "--enable-mpi-thread-multiple, the default since 3.0)")
                                                   : std::string("MPI_THREAD_FUNNELED")));
  }
  world_ = std::make_unique<MpiCommunicator>(MPI_COMM_WORLD, &liveness_, ranksOutnumberCores());
  commands_ = std::make_unique<MpiCommandChannel>(&liveness_);
  if (threads == Threads::kWatched) watch_ = std::make_unique<MpiWatchChannel>();
}

MpiEnvironment::~MpiEnvironment() {
  watch_.reset();
  commands_.reset();
  world_.reset();
  MPI_Finalize();
}

Communicator& MpiEnvironment::world() { return *world_; }

CommandChannel& MpiEnvironment::commands() { return *commands_; }

WatchChannel* MpiEnvironment::watch() { return watch_.get(); }

}  // namespace pvr::comm
