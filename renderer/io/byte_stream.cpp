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

namespace {

// The page cache holds a large file in folios of up to 2 MiB (ext4, xfs);
// a mapping whose address agrees with the file offset modulo 2 MiB lets
// the kernel map each such folio with one page-table entry (a PMD) instead
// of 512: the first touch takes one fault per 2 MiB instead of one per
// 64 KiB (fault-around), the ray caster's and the bounds pass's TLB misses
// drop, and the page tables neither cost memory nor take time to tear down.
constexpr std::uint64_t kFolioAlign = std::uint64_t(2) << 20;

// `total` bytes of anonymous zero pages, read-only, whose address is
// congruent to `fileOffset` modulo kFolioAlign where the kernel allows it
// (it trims a larger reservation); nullptr when it maps nothing.
void* reserveAligned(std::size_t total, std::uint64_t fileOffset) {
  const std::size_t slack = std::size_t(kFolioAlign);
  void* wide = ::mmap(nullptr, total + slack, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (wide == MAP_FAILED) return nullptr;
  const auto base = reinterpret_cast<std::uintptr_t>(wide);
  const std::uintptr_t want = std::uintptr_t(fileOffset % kFolioAlign);
  const std::uintptr_t at = base + ((want - base % kFolioAlign + kFolioAlign) % kFolioAlign);
  if (at > base) ::munmap(wide, at - base);
  if (base + total + slack > at + total) ::munmap(reinterpret_cast<void*>(at + total), base + total + slack - (at + total));
  return reinterpret_cast<void*>(at);
}

}  // namespace

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
  void* region = reserveAligned(total, first);
  if (!region) return nullptr;
  if (::mmap(region, fileBytes, PROT_READ, MAP_SHARED | MAP_FIXED, fd_, off_t(first)) == MAP_FAILED) {
    ::munmap(region, total);
    return nullptr;
  }
  // A hint (THP "madvise" mode): map the cache's 2 MiB folios whole.
  (void)::madvise(region, fileBytes, MADV_HUGEPAGE);
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
