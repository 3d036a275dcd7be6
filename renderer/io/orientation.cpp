#include "orientation.h"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "source_util.h"

namespace pvr::core {

bool Orientation::reorders() const {
  return fileAxis != std::array<int, 3>{0, 1, 2} || flipped[0] || flipped[1] || flipped[2];
}

Orientation orientationOf(const IndexFrame& frame, IVec3 dims, std::string_view where) {
  Orientation o;
  std::array<bool, 3> taken{};
  std::array<double, 3> spacing{}, start{};
  for (int a = 0; a < 3; ++a) {
    const Vec3 axis = frame.axes[std::size_t(a)];
    const double len = length(axis);
    if (!(len > 0) || !std::isfinite(len))
      failAt(ErrorCode::kBadFile, where, "index axis " + std::to_string(a) + " has no direction in space");
    // The space axis it lies nearest.
    int w = 0;
    for (int c = 1; c < 3; ++c)
      if (std::fabs(axis[c]) > std::fabs(axis[w])) w = c;
    if (taken[std::size_t(w)])
      failAt(ErrorCode::kBadFile, where,
             "two index axes lie nearest space axis " + std::to_string(w) + "; the orientation is degenerate");
    taken[std::size_t(w)] = true;
    o.fileAxis[std::size_t(w)] = a;
    o.flipped[std::size_t(w)] = axis[w] < 0;
    const double cosine = std::min(1.0, std::fabs(axis[w]) / len);
    o.obliqueDegrees = std::max(o.obliqueDegrees, std::acos(cosine) * 180 / std::numbers::pi);
    spacing[std::size_t(w)] = len;
    // The first node along w is the file's last along a when flipped.
    start[std::size_t(w)] = axis[w] < 0 ? frame.origin[w] - len * double(dims[a] - 1) : frame.origin[w];
  }
  for (int w = 0; w < 3; ++w) {
    o.grid.dims[w] = dims[o.fileAxis[std::size_t(w)]];
    o.grid.spacing[w] = spacing[std::size_t(w)];
    o.grid.origin[w] = start[std::size_t(w)];
  }
  // Below a millionth of a degree is rounding in the header, not a rotation.
  if (o.obliqueDegrees < 1e-6) o.obliqueDegrees = 0;
  return o;
}

std::string obliqueNote(const Orientation& o) {
  if (o.obliqueDegrees == 0) return "";
  char text[96];
  std::snprintf(text, sizeof text, " (oblique by %.3g degrees: shown on the nearest axes)", o.obliqueDegrees);
  return text;
}

std::string obliqueWarning(const Orientation& o) {
  if (o.obliqueDegrees == 0) return "";
  char text[128];
  std::snprintf(text, sizeof text,
                "oblique orientation (%.3g degrees off the axes): rendered axis-aligned on the nearest signed axes",
                o.obliqueDegrees);
  return text;
}

namespace {

class ReorientedSource final : public VolumeSource {
 public:
  ReorientedSource(std::unique_ptr<VolumeSource> inner, const Orientation& o) : inner_(std::move(inner)), o_(o) {}

  const GridGeometry& grid() const override { return o_.grid; }
  ScalarType type() const override { return inner_->type(); }
  bool canReadPartially() const override { return inner_->canReadPartially(); }
  std::string describe() const override {
    return inner_->describe() + (o_.reorders() ? " (reoriented to its space)" : "");
  }
  std::string caveat() const override { return obliqueWarning(o_); }
  void setFineCounts(bool on) override { inner_->setFineCounts(on); }
  void prefetchBox(const NodeBox& stored) const override {
    inner_->prefetchBox(o_.reorders() ? toFile(stored) : stored);
  }

  Brick readBox(const NodeBox& owned, const NodeBox& stored) const override {
    // An oblique file on its own axes needs no reordering, only its caveat.
    if (!o_.reorders()) return inner_->readBox(owned, stored);
    checkReadBoxes(describe(), o_.grid, owned, stored);
    const Brick in = inner_->readBox(toFile(owned), toFile(stored));
    Brick out = Brick::forOverwrite(o_.grid, in.type(), owned, stored);
    dispatchScalar(in.type(), [&](auto tag) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
      copy(in.as<T>(), in, out.as<T>(), stored);
    });
    out.loadTimes().read = in.loadTimes().read;
    out.updateValueRange();
    return out;
  }

 private:
  // The file's index of space node n along space axis w.
  std::int64_t fileIndex(int w, std::int64_t n) const {
    const std::int64_t last = inner_->grid().dims[o_.fileAxis[std::size_t(w)]] - 1;
    return o_.flipped[std::size_t(w)] ? last - n : n;
  }
  NodeBox toFile(const NodeBox& box) const {
    NodeBox f;
    for (int w = 0; w < 3; ++w) {
      const int a = o_.fileAxis[std::size_t(w)];
      const std::int64_t lo = fileIndex(w, box.lo[w]), hi = fileIndex(w, box.hi[w]);
      f.lo[a] = std::min(lo, hi);
      f.hi[a] = std::max(lo, hi);
    }
    return f;
  }
  template <typename T>
  void copy(const T* in, const Brick& inBrick, T* out, const NodeBox& stored) const {
    // Storage strides of the file brick per file axis.
    const IVec3 e = inBrick.stored().extents();
    const std::int64_t stride[3] = {1, e.x, e.x * e.y};
    std::int64_t step[3];
    for (int w = 0; w < 3; ++w)
      step[w] = (o_.flipped[std::size_t(w)] ? -1 : 1) * stride[o_.fileAxis[std::size_t(w)]];
    std::size_t i = 0;
    for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
      for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y) {
        IVec3 first;
        first[o_.fileAxis[0]] = fileIndex(0, stored.lo.x);
        first[o_.fileAxis[1]] = fileIndex(1, y);
        first[o_.fileAxis[2]] = fileIndex(2, z);
        const T* row = in + inBrick.linearIndex(first);
        for (std::int64_t x = stored.lo.x; x <= stored.hi.x; ++x, row += step[0]) out[i++] = *row;
      }
  }

  std::unique_ptr<VolumeSource> inner_;
  Orientation o_;
};

}  // namespace

std::unique_ptr<VolumeSource> reoriented(std::unique_ptr<VolumeSource> inner, const Orientation& o) {
  if (!o.reorders() && o.obliqueDegrees == 0) return inner;
  return std::make_unique<ReorientedSource>(std::move(inner), o);
}

}  // namespace pvr::core
