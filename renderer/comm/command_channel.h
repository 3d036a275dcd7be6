// The master's commands to the other ranks of a job, on a message space of
// their own so that they never match the messages and collectives the
// commands then run. Rank 0 posts; every other rank awaits the next command
// and sleeps between polls, so an idle job costs no CPU.
#pragma once

#include "communicator.h"

namespace pvr::comm {

class CommandChannel {
 public:
  virtual ~CommandChannel() = default;
  // Rank 0: sends `command` to every other rank.
  virtual void post(std::span<const std::byte> command) = 0;
  // Other ranks: the next command rank 0 posts.
  virtual Bytes await() = 0;
  // Ends the whole job at once: a broken transport, not a user error.
  [[noreturn]] virtual void abortJob(int status) = 0;
};

}  // namespace pvr::comm
