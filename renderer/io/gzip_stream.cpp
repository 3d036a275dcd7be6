#include "gzip_stream.h"

#include <zlib.h>

#include <algorithm>
#include <vector>

#include "source_util.h"

namespace pvr::core {

namespace {
constexpr std::size_t kInputChunk = std::size_t(1) << 16;
constexpr std::size_t kDiscardChunk = std::size_t(1) << 16;
// inflate counts output in uInt; stay well inside it.
constexpr std::size_t kMaxInflateRequest = std::size_t(1) << 30;
}  // namespace

struct GzipStream::State {
  FileStream file;
  std::uint64_t fileOffset;    // next compressed byte to read from the file
  bool fileEnded = false;      // no compressed bytes left in the file
  bool dataEnded = false;      // the last gzip member has ended
  std::uint64_t decoded = 0;   // decoded bytes produced so far
  z_stream zs{};
  std::vector<unsigned char> input = std::vector<unsigned char>(kInputChunk);
  std::vector<std::byte> discard;

  State(const std::string& path, std::uint64_t start) : file(path), fileOffset(start) {}
};

GzipStream::GzipStream(const std::string& path, std::uint64_t start)
    : s_(std::make_unique<State>(path, start)) {
  // 15 + 32: accept gzip and zlib headers alike (some NRRD writers emit zlib).
  if (inflateInit2(&s_->zs, 15 + 32) != Z_OK)
    failAt(ErrorCode::kInternal, s_->file.where(), "cannot initialise zlib");
}

GzipStream::~GzipStream() { inflateEnd(&s_->zs); }

void GzipStream::refill() {
  const std::size_t got = s_->file.readSome(
      s_->fileOffset, reinterpret_cast<std::byte*>(s_->input.data()), s_->input.size());
  s_->fileOffset += got;
  s_->fileEnded = got == 0;
  s_->zs.next_in = s_->input.data();
  s_->zs.avail_in = uInt(got);
}

std::size_t GzipStream::decode(std::byte* dst, std::size_t n) {
  State& s = *s_;
  std::size_t produced = 0;
  while (produced < n && !s.dataEnded) {
    if (s.zs.avail_in == 0) {
      refill();
      if (s.fileEnded)
        failAt(ErrorCode::kBadFile, s.file.where(),
               "gzip data is truncated: the compressed stream ends after " +
                   std::to_string(s.decoded) + " decoded bytes");
    }
    // Step: inflate into the caller's buffer, or into scratch when discarding.
    const std::size_t want = std::min(n - produced, dst ? kMaxInflateRequest : kDiscardChunk);
    if (!dst && s.discard.empty()) s.discard.resize(kDiscardChunk);
    s.zs.next_out = reinterpret_cast<Bytef*>(dst ? dst + produced : s.discard.data());
    s.zs.avail_out = uInt(want);
    const int rc = inflate(&s.zs, Z_NO_FLUSH);
    const std::size_t got = want - s.zs.avail_out;
    produced += got;
    s.decoded += got;

    if (rc == Z_STREAM_END) {
      // Step: a gzip file may hold several members back to back; anything
      // else after the end (padding) is not data.
      if (s.zs.avail_in == 0) refill();
      if (s.zs.avail_in > 0 && s.zs.next_in[0] == 0x1f)
        inflateReset(&s.zs);
      else
        s.dataEnded = true;
    } else if (rc == Z_BUF_ERROR && s.zs.avail_in == 0) {
      continue;  // needs more input: the loop refills
    } else if (rc != Z_OK) {
      failAt(ErrorCode::kBadFile, s.file.where(),
             std::string("corrupt gzip data after ") + std::to_string(s.decoded) +
                 " decoded bytes: " + (s.zs.msg ? s.zs.msg : zError(rc)));
    }
  }
  return produced;
}

void GzipStream::read(std::uint64_t offset, std::byte* dst, std::size_t n) {
  State& s = *s_;
  if (offset < s.decoded)
    failAt(ErrorCode::kInternal, s.file.where(), "gzip stream cannot seek backwards");
  // Step: skip forward to the run, then decode it in place.
  const std::uint64_t skip = offset - s.decoded;
  if (decode(nullptr, skip) != skip || decode(dst, n) != n)
    failAt(ErrorCode::kBadFile, s.file.where(),
           "gzip data ends after " + std::to_string(s.decoded) + " decoded bytes, reading needs " +
               std::to_string(offset + n));
}

std::uint64_t GzipStream::decodeToEnd() {
  while (decode(nullptr, kDiscardChunk) == kDiscardChunk) {
  }
  return s_->decoded;
}

std::uint64_t gzipDecodedSize(const std::string& path, std::uint64_t start, std::uint64_t expected) {
  // Step: the fast path reads the last member's ISIZE (little-endian, mod 2^32).
  constexpr std::uint64_t kMinGzipBytes = 18;  // 10-byte header + 8-byte trailer
  FileStream file(path);
  const std::uint64_t size = fileSizeOf(path);
  if (size >= start + kMinGzipBytes) {
    unsigned char trailer[4];
    file.read(size - 4, reinterpret_cast<std::byte*>(trailer), 4);
    const std::uint32_t isize = std::uint32_t(trailer[0]) | std::uint32_t(trailer[1]) << 8 |
                                std::uint32_t(trailer[2]) << 16 | std::uint32_t(trailer[3]) << 24;
    if (isize == std::uint32_t(expected)) return expected;
  }
  // Step: disagreement (or a zlib stream, or a truncated file): count exactly.
  GzipStream stream(path, start);
  return stream.decodeToEnd();
}

}  // namespace pvr::core
