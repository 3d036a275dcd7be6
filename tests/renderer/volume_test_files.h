// Writers of small test volumes in every supported format, written here by
// hand (headers as text or structs, gzip through zlib) so the loaders are
// checked against files they did not produce, with voxel values the tests chose.
#pragma once

#include <nifti/nifti1.h>
#include <zlib.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "error.h"
#include "io/volume_io.h"
#include "test_files.h"

namespace pvr::core::test {

namespace fs = std::filesystem;

constexpr ScalarType kAllTypes[] = {ScalarType::kUInt8, ScalarType::kUInt16, ScalarType::kInt16,
                                    ScalarType::kFloat32};

struct TestVolume {
  GridGeometry grid;
  ScalarType type = ScalarType::kUInt8;
};

inline TestVolume testVolume(ScalarType type) {
  TestVolume v;
  v.type = type;
  v.grid.dims = {9, 7, 5};
  v.grid.spacing = {0.5, 0.75, 2.25};  // anisotropic
  v.grid.origin = {-3.5, 1.25, 10.0};
  return v;
}

// A pattern that fills every byte of the type (catches swapped or shifted
// bytes), including negative and fractional values.
inline double patternValue(ScalarType type, IVec3 n) {
  const std::int64_t i = n.x + 13 * n.y + 101 * n.z;
  switch (type) {
    case ScalarType::kUInt8: return double((i * 37 + 11) % 256);
    case ScalarType::kUInt16: return double((i * 2671 + 13) % 65536);
    case ScalarType::kInt16: return double((i * 2671 + 13) % 65536 - 32768);
    case ScalarType::kFloat32: break;
  }
  return double(float(double(i) * 0.37 - 55.5));
}

// The voxels in file order, little- or big-endian.
inline std::vector<std::byte> voxelData(const TestVolume& v, bool bigEndian) {
  const std::size_t size = scalarSize(v.type);
  std::vector<std::byte> out;
  out.reserve(std::size_t(v.grid.dims.product()) * size);
  for (std::int64_t z = 0; z < v.grid.dims.z; ++z)
    for (std::int64_t y = 0; y < v.grid.dims.y; ++y)
      for (std::int64_t x = 0; x < v.grid.dims.x; ++x) {
        const double value = patternValue(v.type, {x, y, z});
        std::byte b[4];
        dispatchScalar(v.type, [&](auto tag) {
          using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
          const T t = T(value);
          std::memcpy(b, &t, sizeof t);
        });
        if (bigEndian) std::reverse(b, b + size);
        out.insert(out.end(), b, b + size);
      }
  return out;
}

inline std::vector<std::byte> textBytes(const std::string& s) {
  const auto* p = reinterpret_cast<const std::byte*>(s.data());
  return {p, p + s.size()};
}

inline std::vector<std::byte> concat(std::vector<std::byte> a, const std::vector<std::byte>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

inline void writeBytes(const std::string& path, const std::vector<std::byte>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  REQUIRE(out.good());
}

inline std::vector<std::byte> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> c((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto* p = reinterpret_cast<const std::byte*>(c.data());
  return {p, p + c.size()};
}

// A single gzip member (deflate with the gzip wrapper, as gzip(1) writes).
inline std::vector<std::byte> gzipBytes(const std::vector<std::byte>& in) {
  z_stream zs{};
  REQUIRE(deflateInit2(&zs, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) == Z_OK);
  std::vector<std::byte> out(deflateBound(&zs, uLong(in.size())) + 32);
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in.data()));
  zs.avail_in = uInt(in.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = uInt(out.size());
  REQUIRE(deflate(&zs, Z_FINISH) == Z_STREAM_END);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

inline std::string triple(Vec3 v, const char* sep = " ") {
  std::ostringstream s;
  s.precision(17);
  s << v.x << sep << v.y << sep << v.z;
  return s.str();
}

// ---- raw + JSON sidecar -------------------------------------------------

inline std::string writeRawJson(const std::string& dir, const std::string& name, const TestVolume& v,
                                bool bigEndian) {
  writeBytes(dir + "/" + name + ".raw", voxelData(v, bigEndian));
  std::ostringstream j;
  j << "{\n  \"dims\": [" << v.grid.dims.x << ", " << v.grid.dims.y << ", " << v.grid.dims.z
    << "],\n  \"dtype\": \"" << scalarName(v.type) << "\",\n  \"spacing\": ["
    << triple(v.grid.spacing, ", ") << "],\n  \"origin\": [" << triple(v.grid.origin, ", ")
    << "],\n  \"raw_file\": \"" << name << ".raw\",\n  \"endian\": \""
    << (bigEndian ? "big" : "little")
    << "\",\n  \"source\": \"written by volume tests\",\n  \"stats\": {\"min\": 0}\n}\n";
  const std::string path = dir + "/" + name + ".json";
  writeBytes(path, textBytes(j.str()));
  return path;
}

// ---- NRRD ------------------------------------------------------------------

struct NrrdOptions {
  bool attached = true;
  bool gzip = false;
  bool bigEndian = false;
  bool spaceDirections = false;  // "space directions" + "space origin" instead of "spacings" + "axis mins"
  int lineSkip = 0;              // junk lines before the data
  int byteSkip = 0;              // junk bytes after them (decoded bytes for gzip)
  std::string typeName{};        // NRRD type spelling; empty: a default alias per type
  std::string newline = "\n";
};

inline std::string nrrdTypeName(ScalarType t) {
  switch (t) {
    case ScalarType::kUInt8: return "uchar";
    case ScalarType::kUInt16: return "unsigned short";
    case ScalarType::kInt16: return "short";
    case ScalarType::kFloat32: break;
  }
  return "float";
}

inline std::string writeNrrd(const std::string& dir, const std::string& name, const TestVolume& v,
                             const NrrdOptions& o) {
  const std::string nl = o.newline;
  const std::string dataName = name + (o.gzip ? ".raw.gz" : ".raw");
  std::ostringstream h;
  h << "NRRD0004" << nl << "# written by volume tests" << nl
    << "type: " << (o.typeName.empty() ? nrrdTypeName(v.type) : o.typeName) << nl
    << "dimension: 3" << nl << "sizes: " << v.grid.dims.x << " " << v.grid.dims.y << " "
    << v.grid.dims.z << nl;
  if (o.spaceDirections) {
    h << "space: left-posterior-superior" << nl << "space directions: (" << v.grid.spacing.x
      << ",0,0) (0," << v.grid.spacing.y << ",0) (0,0," << v.grid.spacing.z << ")" << nl
      << "space origin: (" << triple(v.grid.origin, ",") << ")" << nl;
  } else {
    h << "spacings: " << triple(v.grid.spacing) << nl << "axis mins: " << triple(v.grid.origin) << nl;
  }
  h << "kinds: domain domain domain" << nl << "encoding: " << (o.gzip ? "gzip" : "raw") << nl
    << "endian: " << (o.bigEndian ? "big" : "little") << nl << "note:=key/value pairs are ignored" << nl;
  if (o.lineSkip) h << "line skip: " << o.lineSkip << nl;
  if (o.byteSkip) h << "byte skip: " << o.byteSkip << nl;
  if (!o.attached) h << "data file: " << dataName << nl;
  h << nl;

  // Data: junk lines (raw file bytes), then junk bytes (decoded bytes for gzip), then voxels.
  std::string lines;
  for (int i = 0; i < o.lineSkip; ++i) lines += "junk line " + std::to_string(i) + "\n";
  std::vector<std::byte> payload(std::size_t(o.byteSkip), std::byte{0xAB});
  payload = concat(payload, voxelData(v, o.bigEndian));
  if (o.gzip) payload = gzipBytes(payload);
  const std::vector<std::byte> data = concat(textBytes(lines), payload);

  const std::string path = dir + "/" + name + (o.attached ? ".nrrd" : ".nhdr");
  if (o.attached) {
    writeBytes(path, concat(textBytes(h.str()), data));
  } else {
    writeBytes(path, textBytes(h.str()));
    writeBytes(dir + "/" + dataName, data);
  }
  return path;
}

// ---- NIfTI-1 ---------------------------------------------------------------

template <typename T>
void swapField(T& v) {
  auto* b = reinterpret_cast<unsigned char*>(&v);
  std::reverse(b, b + sizeof v);
}
template <typename T, std::size_t N>
void swapField(T (&a)[N]) {
  for (T& v : a) swapField(v);
}

// Byte-swaps every numeric field of the 348-byte header.
inline void swapHeader(nifti_1_header& h) {
  swapField(h.sizeof_hdr); swapField(h.extents); swapField(h.session_error); swapField(h.dim);
  swapField(h.intent_p1); swapField(h.intent_p2); swapField(h.intent_p3);
  swapField(h.intent_code); swapField(h.datatype); swapField(h.bitpix); swapField(h.slice_start);
  swapField(h.pixdim); swapField(h.vox_offset); swapField(h.scl_slope); swapField(h.scl_inter);
  swapField(h.slice_end); swapField(h.cal_max); swapField(h.cal_min); swapField(h.slice_duration);
  swapField(h.toffset); swapField(h.glmax); swapField(h.glmin); swapField(h.qform_code);
  swapField(h.sform_code); swapField(h.quatern_b); swapField(h.quatern_c); swapField(h.quatern_d);
  swapField(h.qoffset_x); swapField(h.qoffset_y); swapField(h.qoffset_z);
  swapField(h.srow_x); swapField(h.srow_y); swapField(h.srow_z);
}

inline short niftiDatatype(ScalarType t) {
  switch (t) {
    case ScalarType::kUInt8: return DT_UINT8;
    case ScalarType::kUInt16: return DT_UINT16;
    case ScalarType::kInt16: return DT_INT16;
    case ScalarType::kFloat32: break;
  }
  return DT_FLOAT32;
}

struct NiftiOptions {
  bool gzip = false;
  bool bigEndian = false;
  float slope = 0, inter = 0;  // scl_slope 0: no scaling
  short datatype = 0;          // 0: the volume's type
};

inline nifti_1_header niftiHeader(const TestVolume& v, const NiftiOptions& o) {
  nifti_1_header h{};
  h.sizeof_hdr = 348;
  h.dim[0] = 3;
  for (int a = 0; a < 3; ++a) {
    h.dim[a + 1] = short(v.grid.dims[a]);
    h.pixdim[a + 1] = float(v.grid.spacing[a]);
  }
  for (int d = 4; d < 8; ++d) h.dim[d] = 1;
  h.pixdim[0] = 1;  // qfac
  h.datatype = o.datatype ? o.datatype : niftiDatatype(v.type);
  h.bitpix = short(8 * scalarSize(v.type));
  h.vox_offset = 352;
  h.scl_slope = o.slope;
  h.scl_inter = o.inter;
  h.qform_code = 1;  // scanner; identity rotation (quatern_b..d = 0)
  h.qoffset_x = float(v.grid.origin.x);
  h.qoffset_y = float(v.grid.origin.y);
  h.qoffset_z = float(v.grid.origin.z);
  h.xyzt_units = NIFTI_UNITS_MM;
  std::memcpy(h.magic, "n+1", 4);
  return h;
}

// Replaces the qform with an sform whose rows are `rows` (scanner = rows * (i, j, k, 1)).
inline void setSform(nifti_1_header& h, const float (&rows)[3][4]) {
  h.qform_code = 0;
  h.sform_code = 2;
  std::memcpy(h.srow_x, rows[0], sizeof h.srow_x);
  std::memcpy(h.srow_y, rows[1], sizeof h.srow_y);
  std::memcpy(h.srow_z, rows[2], sizeof h.srow_z);
}

inline std::vector<std::byte> niftiBytes(nifti_1_header h, const TestVolume& v, bool bigEndian) {
  if (bigEndian) swapHeader(h);
  const auto* p = reinterpret_cast<const std::byte*>(&h);
  std::vector<std::byte> out(p, p + sizeof h);
  out.resize(352);  // 4-byte extension flag, all zero: no extensions
  return concat(out, voxelData(v, bigEndian));
}

inline std::string writeNifti(const std::string& dir, const std::string& name, const TestVolume& v,
                              const NiftiOptions& o) {
  std::vector<std::byte> bytes = niftiBytes(niftiHeader(v, o), v, o.bigEndian);
  const std::string path = dir + "/" + name + (o.gzip ? ".nii.gz" : ".nii");
  writeBytes(path, o.gzip ? gzipBytes(bytes) : bytes);
  return path;
}

// ---- checks ------------------------------------------------------------------

// Every stored node of `brick` equals the pattern, exactly.
inline void requirePattern(const Brick& brick, ScalarType patternType) {
  const NodeBox& s = brick.stored();
  std::int64_t mismatches = 0;
  for (std::int64_t z = s.lo.z; z <= s.hi.z; ++z)
    for (std::int64_t y = s.lo.y; y <= s.hi.y; ++y)
      for (std::int64_t x = s.lo.x; x <= s.hi.x; ++x)
        if (brick.valueAt({x, y, z}) != patternValue(patternType, {x, y, z})) {
          if (mismatches++ == 0)
            FAIL_CHECK("first mismatch at (" << x << "," << y << "," << z << "): read "
                                             << brick.valueAt({x, y, z}) << ", wrote "
                                             << patternValue(patternType, {x, y, z}));
        }
  REQUIRE(mismatches == 0);
}

// The boxes every format must read right: whole, interior with ghosts (short
// x runs), whole rows, whole slabs, single nodes at both corners.
inline std::vector<std::pair<NodeBox, NodeBox>> testBoxes(const GridGeometry& g) {
  const IVec3 m{g.dims.x - 1, g.dims.y - 1, g.dims.z - 1};
  const NodeBox owned{{2, 2, 1}, {5, 4, 3}};
  return {
      {g.allNodes(), g.allNodes()},
      {owned, owned.grown(1).intersect(g.allNodes())},
      {{{0, 2, 1}, {m.x, 5, 3}}, {{0, 1, 0}, {m.x, 6, 4}}},
      {{{0, 0, 2}, {m.x, m.y, 3}}, {{0, 0, 1}, {m.x, m.y, 4}}},
      {{{0, 0, 0}, {0, 0, 0}}, {{0, 0, 0}, {0, 0, 0}}},
      {{m, m}, {m, m}},
  };
}

// Opens `path` and checks grid, type, partial-read ability and every test box.
inline void requireRoundTrip(const std::string& path, const TestVolume& v, bool partial) {
  INFO(path << " as " << scalarName(v.type));
  const auto src = openVolumeFile(path);
  REQUIRE(src->type() == v.type);
  REQUIRE(src->grid().dims == v.grid.dims);
  REQUIRE(src->grid().spacing.x == Approx(v.grid.spacing.x));
  REQUIRE(src->grid().spacing.y == Approx(v.grid.spacing.y));
  REQUIRE(src->grid().spacing.z == Approx(v.grid.spacing.z));
  REQUIRE(src->grid().origin.x == Approx(v.grid.origin.x));
  REQUIRE(src->grid().origin.y == Approx(v.grid.origin.y));
  REQUIRE(src->grid().origin.z == Approx(v.grid.origin.z));
  REQUIRE(src->canReadPartially() == partial);
  for (const auto& [owned, stored] : testBoxes(v.grid)) {
    INFO("box " << toString(stored) << " owning " << toString(owned));
    const Brick b = src->readBox(owned, stored);
    REQUIRE(b.owned() == owned);
    REQUIRE(b.stored() == stored);
    requirePattern(b, v.type);
  }
}

}  // namespace pvr::core::test
