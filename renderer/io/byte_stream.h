// Byte streams the raw box reader pulls voxel runs from.
//
// The reader asks for runs in increasing offset order, so one interface
// serves both a file read in place (pread at any offset: a brick costs I/O
// proportional to its size) and a compressed stream that can only go forward
// (it decodes and discards what lies between runs).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace pvr::core {

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  // Copies bytes [offset, offset + n) of the (decoded) stream into dst.
  // Offsets never decrease from one call to the next. Throws pvr::Error
  // naming the file when the bytes are not there.
  virtual void read(std::uint64_t offset, std::byte* dst, std::size_t n) = 0;
  // A hint that bytes [offset, offset + n) will be read soon: a file starts
  // reading them in the background, so a reader whose runs are not one
  // sequential stream (a brick's slabs, with other ranks' rows between
  // them) keeps the disk busy instead of waiting on each run in turn.
  // A forward-only stream decodes in order anyway: it ignores the hint.
  virtual void willNeed(std::uint64_t /*offset*/, std::size_t /*n*/) {}
  // Bytes [offset, offset + n) in place, read-only, followed by at least
  // `padding` readable bytes, kept for as long as the pointer lives (beyond
  // the stream); or null when the stream cannot lend them (a compressed
  // stream, a kernel that refuses to map). A reader whose brick is one run
  // of the file holds the file's own pages instead of a copy: no memory of
  // its own to fault in and fill, nothing held twice.
  virtual std::shared_ptr<const std::byte> lend(std::uint64_t /*offset*/, std::size_t /*n*/,
                                                std::size_t /*padding*/) {
    return nullptr;
  }
};

// A file opened read-only for positioned reads; closes it on destruction.
class FileStream final : public ByteStream {
 public:
  // Error messages start with `path`.
  explicit FileStream(const std::string& path);
  ~FileStream() override;
  FileStream(const FileStream&) = delete;
  FileStream& operator=(const FileStream&) = delete;

  // Reads exactly n bytes at offset; throws if the file ends first.
  void read(std::uint64_t offset, std::byte* dst, std::size_t n) override;
  void willNeed(std::uint64_t offset, std::size_t n) override;
  // Reads up to n bytes at offset; returns how many (fewer only at the end of the file).
  std::size_t readSome(std::uint64_t offset, std::byte* dst, std::size_t n);
  // Maps the range read-only (MAP_SHARED: the page cache's own pages), at
  // an address that agrees with the file offset modulo 2 MiB so the
  // cache's large folios map whole (byte_stream.cpp); the padding past it
  // is the file's next bytes or zero pages. Checks the
  // file still holds the range first: a file cut shorter while mapped
  // faults (SIGBUS) where read() would have reported it, so a volume file
  // must not be truncated while a session renders it.
  std::shared_ptr<const std::byte> lend(std::uint64_t offset, std::size_t n, std::size_t padding) override;
  const std::string& where() const { return where_; }

 private:
  int fd_ = -1;
  std::string where_;
};

}  // namespace pvr::core
