// Round trips through every file format: a volume of every scalar type,
// written by hand in a scratch directory, read back whole and as sub-boxes,
// voxel for voxel.
#include <teem/nrrd.h>

#include <catch2/catch.hpp>

#include "volume_test_files.h"

using namespace pvr::core;
using namespace pvr::core::test;

namespace {

// A kind of file the loaders read, and how to write one.
struct FileKind {
  const char* name;
  bool partial;                 // canReadPartially expected
  std::vector<bool> bigEndian;  // the byte orders to write
  std::string (*write)(const std::string& dir, const std::string& name, const TestVolume& v, bool big);
};

const FileKind kFileKinds[] = {
    {"raw+json", true, {false, true},
     [](const std::string& d, const std::string& n, const TestVolume& v, bool big) { return writeRawJson(d, n, v, big); }},
    {"nrrd attached raw", true, {false, true},
     [](const std::string& d, const std::string& n, const TestVolume& v, bool big) {
       return writeNrrd(d, n, v, {.bigEndian = big});
     }},
    {"nrrd attached gzip", false, {false, true},
     [](const std::string& d, const std::string& n, const TestVolume& v, bool big) {
       return writeNrrd(d, n, v, {.gzip = true, .bigEndian = big});
     }},
    {"nhdr detached raw", true, {false},
     [](const std::string& d, const std::string& n, const TestVolume& v, bool big) {
       return writeNrrd(d, n, v, {.attached = false, .bigEndian = big, .spaceDirections = true});
     }},
    {"nhdr detached gzip", false, {true},
     [](const std::string& d, const std::string& n, const TestVolume& v, bool big) {
       return writeNrrd(d, n, v, {.attached = false, .gzip = true, .bigEndian = big});
     }},
    {"nii", true, {false, true},
     [](const std::string& d, const std::string& n, const TestVolume& v, bool big) {
       return writeNifti(d, n, v, {.bigEndian = big});
     }},
    {"nii.gz", false, {false},
     [](const std::string& d, const std::string& n, const TestVolume& v, bool big) {
       return writeNifti(d, n, v, {.gzip = true, .bigEndian = big});
     }},
};

}  // namespace

TEST_CASE("every format reads every scalar type whole and in sub-boxes, in each byte order", "[io]") {
  int k = 0;
  for (const FileKind& kind : kFileKinds) {
    INFO(kind.name);
    const std::string dir = scratchDir("round_trip_" + std::to_string(k++));
    for (ScalarType t : kAllTypes)
      for (bool big : kind.bigEndian) {
        const TestVolume v = testVolume(t);
        const std::string name = std::string(scalarName(t)) + (big ? "_be" : "_le");
        requireRoundTrip(kind.write(dir, name, v, big), v, kind.partial);
      }
  }
  // A .raw finds its sidecar beside it.
  const std::string dir = scratchDir("raw_beside_json");
  const TestVolume v = testVolume(ScalarType::kUInt16);
  writeRawJson(dir, "v", v, true);
  requireRoundTrip(dir + "/v.raw", v, true);
}

TEST_CASE("nrrd line skip and byte skip place the data, raw and gzip", "[io]") {
  const std::string dir = scratchDir("nrrd_skips");
  const TestVolume v = testVolume(ScalarType::kInt16);
  for (bool attached : {true, false})
    for (bool gzip : {false, true}) {
      NrrdOptions o;
      o.attached = attached;
      o.gzip = gzip;
      o.lineSkip = 3;
      o.byteSkip = 17;
      const std::string name = std::string(attached ? "attached" : "detached") + (gzip ? "_gz" : "_raw");
      requireRoundTrip(writeNrrd(dir, name, v, o), v, !gzip);
    }
}

TEST_CASE("nrrd byte skip -1 takes the data from the end of the file", "[io]") {
  const std::string dir = scratchDir("nrrd_byte_skip_end");
  const TestVolume v = testVolume(ScalarType::kFloat32);
  NrrdOptions o;
  o.attached = false;
  const std::string path = writeNrrd(dir, "v", v, o);
  // Prepend a 100-byte preamble to the data file and let byte skip -1 find the voxels.
  const std::string raw = dir + "/v.raw";
  writeBytes(raw, concat(std::vector<std::byte>(100, std::byte{7}), readBytes(raw)));
  std::string header(reinterpret_cast<const char*>(readBytes(path).data()), readBytes(path).size());
  header.insert(header.find("data file:"), "byte skip: -1\n");
  writeBytes(path, textBytes(header));
  requireRoundTrip(path, v, true);
}

TEST_CASE("nrrd accepts its type aliases, CRLF lines, comments and key/value pairs", "[io]") {
  const std::string dir = scratchDir("nrrd_aliases");
  const std::pair<const char*, ScalarType> aliases[] = {
      {"uint8", ScalarType::kUInt8},           {"unsigned char", ScalarType::kUInt8},
      {"uint8_t", ScalarType::kUInt8},         {"ushort", ScalarType::kUInt16},
      {"uint16", ScalarType::kUInt16},         {"unsigned short int", ScalarType::kUInt16},
      {"int16", ScalarType::kInt16},           {"short int", ScalarType::kInt16},
      {"signed short", ScalarType::kInt16},    {"signed short int", ScalarType::kInt16},
      {"int16_t", ScalarType::kInt16},         {"float", ScalarType::kFloat32},
  };
  int i = 0;
  for (const auto& [alias, type] : aliases) {
    NrrdOptions o;
    o.typeName = alias;
    o.newline = (i % 2) ? "\r\n" : "\n";
    requireRoundTrip(writeNrrd(dir, "alias" + std::to_string(i++), testVolume(type), o), testVolume(type), true);
  }
}

TEST_CASE("nrrd files written here load identically in Teem", "[io]") {
  // Identity: Teem's nrrdLoad and our reader agree byte for byte, so the
  // hand-written test files (and our reading of skips and gzip) follow NRRD.
  const std::string dir = scratchDir("nrrd_teem");
  int i = 0;
  for (ScalarType t : kAllTypes)
    for (bool gzip : {false, true}) {
      NrrdOptions o;
      o.gzip = gzip;
      o.attached = (i % 2) == 0;
      o.bigEndian = (i % 3) == 0;
      o.lineSkip = 2;
      o.byteSkip = 5;
      o.spaceDirections = (i % 2) == 1;
      const TestVolume v = testVolume(t);
      const std::string path = writeNrrd(dir, "teem" + std::to_string(i++), v, o);
      INFO(path);
      Nrrd* nrrd = nrrdNew();
      if (nrrdLoad(nrrd, path.c_str(), nullptr) != 0) {
        char* err = biffGetDone(NRRD);
        const std::string message = err;
        free(err);
        nrrdNuke(nrrd);
        FAIL("Teem cannot load it: " << message);
      }
      const Brick ours = openVolumeFile(path)->readAll();
      REQUIRE(nrrdElementSize(nrrd) == scalarSize(t));
      REQUIRE(nrrdElementNumber(nrrd) == std::size_t(v.grid.dims.product()));
      CHECK(std::memcmp(nrrd->data, ours.bytes(), ours.byteSize()) == 0);
      nrrdNuke(nrrd);
    }
}

TEST_CASE("nii applies scl_slope and scl_inter, turning the volume into float32", "[io]") {
  const std::string dir = scratchDir("nii_scaled");
  const TestVolume v = testVolume(ScalarType::kInt16);
  NiftiOptions o;
  o.slope = 2;
  o.inter = -1;
  const auto src = openVolumeFile(writeNifti(dir, "scaled", v, o));
  REQUIRE(src->type() == ScalarType::kFloat32);
  REQUIRE(src->canReadPartially());
  const Brick b = src->readBox({{1, 1, 1}, {3, 3, 3}}, {{0, 0, 0}, {4, 4, 4}});
  for (std::int64_t z = 0; z <= 4; ++z)
    for (std::int64_t y = 0; y <= 4; ++y)
      for (std::int64_t x = 0; x <= 4; ++x)
        REQUIRE(b.valueAt({x, y, z}) == 2 * patternValue(v.type, {x, y, z}) - 1);
}

TEST_CASE("nii takes the origin from the sform when there is no qform", "[io]") {
  const std::string dir = scratchDir("nii_sform");
  const TestVolume v = testVolume(ScalarType::kUInt8);
  nifti_1_header h = niftiHeader(v, {});
  setSform(h, {{0.5f, 0, 0, 7.5f}, {0, 0.75f, 0, -2.0f}, {0, 0, 2.25f, 3.0f}});
  writeBytes(dir + "/s.nii", niftiBytes(h, v, false));
  const auto src = openVolumeFile(dir + "/s.nii");
  CHECK(src->grid().origin == Vec3{7.5, -2.0, 3.0});
  CHECK(src->grid().spacing == Vec3{0.5, 0.75, 2.25});
}

TEST_CASE("a raw volume reads a small box of a 1 GiB file without reading the rest", "[io]") {
  // A sparse 1024^3 uint8 file: only the box's bytes are ever touched, so
  // this is quick and costs no memory beyond the box.
  const std::string dir = scratchDir("raw_sparse");
  const std::string raw = dir + "/big.raw";
  { std::ofstream(raw, std::ios::binary); }
  std::error_code ec;
  fs::resize_file(raw, std::uint64_t(1) << 30, ec);
  if (ec) {
    WARN("cannot create a sparse 1 GiB file in " << dir << ": " << ec.message());
    return;
  }
  const IVec3 n{700, 300, 900};
  {
    std::fstream f(raw, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(std::streamoff((n.z * 1024 + n.y) * 1024 + n.x));
    f.put(char(42));
  }
  writeBytes(dir + "/big.json",
             textBytes(R"({"dims": [1024, 1024, 1024], "dtype": "uint8", "spacing": [1, 1, 1], "raw_file": "big.raw"})"));
  const auto src = openVolumeFile(dir + "/big.json");
  const NodeBox box{{698, 298, 898}, {702, 302, 902}};
  const Brick b = src->readBox(box, box);
  CHECK(b.valueAt(n) == 42);
  CHECK(b.valueAt({698, 298, 898}) == 0);
  CHECK(b.valueRange().max == 42);
  CHECK(b.byteSize() == 125);
}

TEST_CASE("openVolumeFile lists the formats it knows", "[io]") {
  REQUIRE(volumeFormats().size() == 4);
  for (const VolumeFormat& f : volumeFormats()) CHECK(std::string(f.extensions).size() > 0);
  // The series sidecar comes first: raw+json would take any .json.
  CHECK(volumeFormats()[0].matches("run.SERIES.json"));
  CHECK_FALSE(volumeFormats()[0].matches("ct.json"));
  CHECK(volumeFormats()[2].matches("/x/CT.NHDR"));
  CHECK(volumeFormats()[3].matches("brain.nii.gz"));
  CHECK_FALSE(volumeFormats()[1].matches("brain.nii.gz"));
}

TEST_CASE("writeRawJsonVolume writes what openVolumeFile reads back, voxel for voxel", "[io]") {
  const std::string dir = scratchDir("write_raw_json");
  const Brick written = openProcedural("shepp-logan", {9, 7, 5}, Vec3{0.5, 0.25, 2})->readAll();
  const std::string sidecar = writeRawJsonVolume(written, dir + "/sub", "phantom", "a test volume");
  CHECK(sidecar == dir + "/sub/phantom.json");
  const Brick read = openVolumeFile(sidecar)->readAll();
  CHECK(read.type() == written.type());
  CHECK(read.grid().dims == written.grid().dims);
  CHECK(read.grid().spacing == written.grid().spacing);
  CHECK(read.grid().origin == written.grid().origin);
  REQUIRE(read.byteSize() == written.byteSize());
  CHECK(std::memcmp(read.bytes(), written.bytes(), read.byteSize()) == 0);
}
