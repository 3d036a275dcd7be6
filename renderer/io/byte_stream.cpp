#include "byte_stream.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "source_util.h"

namespace pvr::core {

FileStream::FileStream(const std::string& path) : where_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0)
    failAt(ErrorCode::kIo, where_, errno == ENOENT ? "no such file" : std::strerror(errno));
}

FileStream::~FileStream() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t FileStream::readSome(std::uint64_t offset, std::byte* dst, std::size_t n) {
  // pread may return less than asked (signals, >2 GiB requests): loop until
  // the request is met or the file ends.
  constexpr std::size_t kMaxChunk = std::size_t(1) << 30;
  std::size_t done = 0;
  while (done < n) {
    const ssize_t got = ::pread(fd_, dst + done, std::min(n - done, kMaxChunk),
                                off_t(offset + done));
    if (got < 0) {
      if (errno == EINTR) continue;
      failAt(ErrorCode::kIo, where_, std::string("read failed: ") + std::strerror(errno));
    }
    if (got == 0) break;
    done += std::size_t(got);
  }
  return done;
}

void FileStream::willNeed(std::uint64_t offset, std::size_t n) {
  // Only a hint: a kernel that refuses it costs speed, not data.
  (void)::posix_fadvise(fd_, off_t(offset), off_t(n), POSIX_FADV_WILLNEED);
}

void FileStream::read(std::uint64_t offset, std::byte* dst, std::size_t n) {
  const std::size_t got = readSome(offset, dst, n);
  // The size was checked when the volume was opened; a short read here means
  // the file shrank since.
  if (got < n)
    failAt(ErrorCode::kBadFile, where_,
           "file ends at byte " + std::to_string(offset + got) + ", reading needs " +
               std::to_string(offset + n) + " (did it change after opening?)");
}

}  // namespace pvr::core
