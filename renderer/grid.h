// The node-centred grid of the rendering contract, and boxes of its nodes.
//
// Voxel (i,j,k) sits at origin + (i,j,k) * spacing; the domain is the box
// from origin to origin + (dims - 1) * spacing. Storage is x fastest, then
// y, then z.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "vec.h"

namespace pvr::core {

enum class ScalarType : std::uint8_t { kUInt8, kUInt16, kInt16, kFloat32 };

std::size_t scalarSize(ScalarType type);
std::string_view scalarName(ScalarType type);  // "uint8", "uint16", "int16", "float32"
// Accepts the names above and common aliases (NRRD's "unsigned char", "short", "float", ...).
// Throws pvr::Error naming `where` for anything else.
ScalarType parseScalarType(std::string_view name, std::string_view where);

// A box of grid nodes, inclusive on both ends: nodes lo..hi on each axis.
// A brick that owns nodes lo..hi samples the cells between them; two bricks
// side by side share the node plane where they meet (A.hi == B.lo).
struct NodeBox {
  IVec3 lo, hi;

  std::int64_t extent(int axis) const { return hi[axis] - lo[axis] + 1; }
  IVec3 extents() const { return {extent(0), extent(1), extent(2)}; }
  std::int64_t nodeCount() const { return extents().product(); }
  bool empty() const { return hi.x < lo.x || hi.y < lo.y || hi.z < lo.z; }
  bool contains(const NodeBox& o) const;
  NodeBox intersect(const NodeBox& o) const;
  NodeBox grown(std::int64_t layers) const;  // lo - layers .. hi + layers
  friend bool operator==(const NodeBox&, const NodeBox&) = default;
};

struct GridGeometry {
  IVec3 dims{1, 1, 1};
  Vec3 origin{0, 0, 0};
  Vec3 spacing{1, 1, 1};

  NodeBox allNodes() const { return {{0, 0, 0}, {dims.x - 1, dims.y - 1, dims.z - 1}}; }
  Vec3 nodePosition(IVec3 n) const {
    return {origin.x + double(n.x) * spacing.x, origin.y + double(n.y) * spacing.y,
            origin.z + double(n.z) * spacing.z};
  }
  Vec3 domainMin() const { return origin; }
  Vec3 domainMax() const { return nodePosition({dims.x - 1, dims.y - 1, dims.z - 1}); }
  Vec3 center() const { return (domainMin() + domainMax()) * 0.5; }
  double minSpacing() const;
  // Throws pvr::Error naming `where` if dims < 1 or spacing is not finite and positive.
  void validate(std::string_view where) const;
};

std::string toString(const NodeBox& box);  // "[0..63]x[0..63]x[10..20]"

}  // namespace pvr::core
