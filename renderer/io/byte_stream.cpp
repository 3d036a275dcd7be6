#include "byte_stream.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
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

std::shared_ptr<const std::byte> FileStream::lend(std::uint64_t offset, std::size_t n, std::size_t padding) {
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode) || n == 0) return nullptr;
  const std::uint64_t size = std::uint64_t(st.st_size);
  if (offset > size || n > size - offset) return nullptr;
  const std::uint64_t page = std::uint64_t(::sysconf(_SC_PAGESIZE));
  const std::uint64_t first = offset / page * page;
  const std::size_t lead = std::size_t(offset - first);
  const std::size_t fileBytes = (lead + n + page - 1) / page * page;         // whole pages of the range
  const std::size_t total = (lead + n + padding + page - 1) / page * page;  // and of its padding
  // Address space for range and padding, anonymous zero pages; the file's
  // pages go over its start, so padding past the file's end reads zero
  // instead of faulting.
  void* region = ::mmap(nullptr, total, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (region == MAP_FAILED) return nullptr;
  if (::mmap(region, fileBytes, PROT_READ, MAP_SHARED | MAP_FIXED, fd_, off_t(first)) == MAP_FAILED) {
    ::munmap(region, total);
    return nullptr;
  }
  std::shared_ptr<const std::byte> whole(static_cast<const std::byte*>(region),
                                         [total](const std::byte* p) { ::munmap(const_cast<std::byte*>(p), total); });
  return {whole, whole.get() + lead};
}

void FileStream::willNeed(std::uint64_t offset, std::size_t n) {
  // Linux reads at most one read-ahead window per WILLNEED call (the
  // larger of the device's read_ahead_kb and max_sectors_kb: 8 MiB on
  // this project's VM, 128 KiB by default) and silently drops the rest,
  // so a 16 MiB slab announced in one call came in half. Calls of the
  // default window each fetch all they name; their I/O merges as before.
  constexpr std::size_t kWindow = std::size_t(128) << 10;
  // Only a hint: a kernel that refuses it costs speed, not data.
  for (std::size_t done = 0; done < n; done += kWindow)
    (void)::posix_fadvise(fd_, off_t(offset + done), off_t(std::min(kWindow, n - done)), POSIX_FADV_WILLNEED);
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
