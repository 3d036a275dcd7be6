#include "grid.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "error.h"

namespace pvr::core {

std::size_t scalarSize(ScalarType type) {
  switch (type) {
    case ScalarType::kUInt8: return 1;
    case ScalarType::kUInt16: return 2;
    case ScalarType::kInt16: return 2;
    case ScalarType::kFloat32: return 4;
  }
  return 0;
}

std::string_view scalarName(ScalarType type) {
  switch (type) {
    case ScalarType::kUInt8: return "uint8";
    case ScalarType::kUInt16: return "uint16";
    case ScalarType::kInt16: return "int16";
    case ScalarType::kFloat32: return "float32";
  }
  return "?";
}

ScalarType parseScalarType(std::string_view name, std::string_view where) {
  struct Alias { std::string_view name; ScalarType type; };
  static constexpr Alias kAliases[] = {
      {"uint8", ScalarType::kUInt8},     {"uchar", ScalarType::kUInt8},
      {"unsigned char", ScalarType::kUInt8}, {"uint8_t", ScalarType::kUInt8},
      {"uint16", ScalarType::kUInt16},   {"ushort", ScalarType::kUInt16},
      {"unsigned short", ScalarType::kUInt16}, {"uint16_t", ScalarType::kUInt16},
      {"int16", ScalarType::kInt16},     {"short", ScalarType::kInt16},
      {"signed short", ScalarType::kInt16}, {"int16_t", ScalarType::kInt16},
      {"float32", ScalarType::kFloat32}, {"float", ScalarType::kFloat32},
  };
  for (const Alias& a : kAliases)
    if (a.name == name) return a.type;
  // A real type this renderer does not render is unsupported, not a bad
  // file: the catalog lists such a volume with a note (catalog_listing.h).
  static constexpr std::string_view kKnown[] = {"float64", "double", "int8", "signed char", "char", "int32", "int",
                                                "uint32", "unsigned int", "int64", "uint64", "longlong",
                                                "ulonglong", "long long", "unsigned long long"};
  for (std::string_view k : kKnown)
    if (k == name)
      throw Error(ErrorCode::kUnsupported, std::string(where) + ": unknown scalar type '" + std::string(name) +
                                               "' (supported: uint8, uint16, int16, float32)");
  throw Error(ErrorCode::kBadFile, std::string(where) + ": unknown scalar type '" +
                                       std::string(name) +
                                       "' (supported: uint8, uint16, int16, float32)");
}

bool NodeBox::contains(const NodeBox& o) const {
  for (int a = 0; a < 3; ++a)
    if (o.lo[a] < lo[a] || o.hi[a] > hi[a]) return false;
  return true;
}

NodeBox NodeBox::intersect(const NodeBox& o) const {
  NodeBox r;
  for (int a = 0; a < 3; ++a) {
    r.lo[a] = std::max(lo[a], o.lo[a]);
    r.hi[a] = std::min(hi[a], o.hi[a]);
  }
  return r;
}

NodeBox NodeBox::grown(std::int64_t layers) const {
  NodeBox r = *this;
  for (int a = 0; a < 3; ++a) {
    r.lo[a] -= layers;
    r.hi[a] += layers;
  }
  return r;
}

double GridGeometry::minSpacing() const {
  return std::min({spacing.x, spacing.y, spacing.z});
}

void GridGeometry::validate(std::string_view where) const {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1)
      throw Error(ErrorCode::kBadFile, std::string(where) + ": dimension " + std::to_string(a) +
                                           " is " + std::to_string(dims[a]) + ", must be >= 1");
    if (!(std::isfinite(spacing[a]) && spacing[a] > 0))
      throw Error(ErrorCode::kBadFile, std::string(where) + ": spacing " + std::to_string(a) +
                                           " must be finite and positive");
    if (!std::isfinite(origin[a]))
      throw Error(ErrorCode::kBadFile, std::string(where) + ": origin must be finite");
  }
}

std::string toString(const NodeBox& b) {
  std::ostringstream s;
  s << '[' << b.lo.x << ".." << b.hi.x << "]x[" << b.lo.y << ".." << b.hi.y << "]x[" << b.lo.z
    << ".." << b.hi.z << ']';
  return s.str();
}

}  // namespace pvr::core
