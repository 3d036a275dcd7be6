#include "raw_reader.h"

#include <algorithm>
#include <bit>

#include "byte_stream.h"
#include "gzip_stream.h"
#include "source_util.h"

namespace pvr::core {

namespace {

void swapBytesInPlace(std::byte* data, std::size_t count, std::size_t size) {
  for (std::size_t i = 0; i < count; ++i)
    std::reverse(data + i * size, data + (i + 1) * size);
}

std::unique_ptr<ByteStream> openStream(const RawLayout& layout) {
  if (layout.encoding == RawEncoding::kGzip)
    return std::make_unique<GzipStream>(layout.dataPath, layout.gzipStart);
  return std::make_unique<FileStream>(layout.dataPath);
}

class RawVolumeSource final : public VolumeSource {
 public:
  RawVolumeSource(std::string name, const GridGeometry& grid, ScalarType type, RawLayout layout)
      : name_(std::move(name)), grid_(grid), type_(type), layout_(std::move(layout)) {}

  const GridGeometry& grid() const override { return grid_; }
  ScalarType type() const override { return type_; }
  bool canReadPartially() const override { return layout_.encoding == RawEncoding::kRaw; }
  Brick readBox(const NodeBox& owned, const NodeBox& stored) const override {
    return readRawBox(layout_, grid_, type_, owned, stored);
  }
  std::string describe() const override { return name_ + ": " + shapeText(grid_, type_); }

 private:
  std::string name_;
  GridGeometry grid_;
  ScalarType type_;
  RawLayout layout_;
};

}  // namespace

std::unique_ptr<VolumeSource> openRawVolume(std::string name, const GridGeometry& grid,
                                            ScalarType type, RawLayout layout, SizeRule rule) {
  const std::string header = layout.headerPath.empty() ? layout.dataPath : layout.headerPath;
  grid.validate(header);
  // Both terms stay below 2^62, so the sum cannot overflow.
  const std::uint64_t data = voxelBytes(grid, type, header);
  if (layout.offset > (std::uint64_t(1) << 62))
    failAt(ErrorCode::kBadFile, header, "data offset " + std::to_string(layout.offset) + " is absurd");
  const std::uint64_t needed = layout.offset + data;

  // Step: compare what the data holds with what the header needs.
  withHeaderNamed(layout, [&] {
    const bool gzip = layout.encoding == RawEncoding::kGzip;
    const std::uint64_t have = gzip ? gzipDecodedSize(layout.dataPath, layout.gzipStart, needed)
                                    : fileSizeOf(layout.dataPath);
    if (have >= needed && (rule == SizeRule::kAtLeast || have == needed)) return;
    std::string what = std::string(gzip ? "gzip data decodes to " : "file has ") +
                       std::to_string(have) + " bytes, header needs " + std::to_string(needed) + " (";
    if (layout.offset > 0) what += std::to_string(layout.offset) + " bytes before the voxels + ";
    failAt(ErrorCode::kBadFile, layout.dataPath, what + shapeText(grid, type) + ")");
  });
  return std::make_unique<RawVolumeSource>(std::move(name), grid, type, std::move(layout));
}

Brick readRawBox(const RawLayout& layout, const GridGeometry& grid, ScalarType type,
                 const NodeBox& owned, const NodeBox& stored) {
  checkReadBoxes(layout.dataPath, grid, owned, stored);
  Brick brick(grid, type, owned, stored);
  const std::size_t size = scalarSize(type);
  const IVec3 d = grid.dims;
  const IVec3 e = stored.extents();

  // Step: find the longest contiguous run. Whole x rows make a y-slab one
  // run; whole slabs make the entire box one run.
  const bool wholeRows = e.x == d.x;
  const bool wholeSlabs = wholeRows && e.y == d.y;
  const std::int64_t runsY = wholeRows ? 1 : e.y;
  const std::int64_t runsZ = wholeSlabs ? 1 : e.z;
  const std::size_t runBytes =
      std::size_t(e.x * (wholeRows ? e.y : 1) * (wholeSlabs ? e.z : 1)) * size;

  // Step: read the runs in file order (a gzip stream only goes forward).
  withHeaderNamed(layout, [&] {
    std::unique_ptr<ByteStream> stream = openStream(layout);
    std::byte* dst = brick.bytes();
    for (std::int64_t k = 0; k < runsZ; ++k) {
      for (std::int64_t j = 0; j < runsY; ++j) {
        const std::int64_t z = stored.lo.z + k;
        const std::int64_t y = stored.lo.y + j;
        const std::uint64_t node = std::uint64_t((z * d.y + y) * d.x + stored.lo.x);
        stream->read(layout.offset + node * size, dst, runBytes);
        dst += runBytes;
      }
    }
  });

  // Step: bring the scalars to host order.
  const bool hostBig = std::endian::native == std::endian::big;
  if (size > 1 && layout.bigEndian != hostBig)
    swapBytesInPlace(brick.bytes(), std::size_t(stored.nodeCount()), size);
  brick.updateValueRange();
  return brick;
}

}  // namespace pvr::core
