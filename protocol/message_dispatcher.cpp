#include "message_dispatcher.h"

namespace pvr::proto {

bool Dispatcher::dispatch(const Message& message, const FrameInfo& info) const {
  if (const auto& handler = handlers_[message.index()]) {
    handler(message, info);
    return true;
  }
  if (fallback_) fallback_(message, info);
  return false;
}

}  // namespace pvr::proto
