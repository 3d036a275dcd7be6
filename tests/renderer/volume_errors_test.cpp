// Bad volume files: each throws pvr::Error whose message starts with the
// file and says what is wrong; none crashes or allocates a size it read.
#include <catch2/catch.hpp>

#include "volume_test_files.h"

using namespace pvr::core;
using namespace pvr::core::test;
using Catch::Contains;
using Catch::StartsWith;

namespace {

void truncateFile(const std::string& path, std::uint64_t drop) {
  fs::resize_file(path, fs::file_size(path) - drop);
}

void replaceInFile(const std::string& path, const std::string& from, const std::string& to) {
  const std::vector<std::byte> bytes = readBytes(path);
  std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  text.replace(at, from.size(), to);
  writeBytes(path, textBytes(text));
}

// Opening and reading everything: some formats can only notice at read time.
void openAndRead(const std::string& path) { openVolumeFile(path)->readAll(); }

pvr::ErrorCode errorCodeOf(const std::string& path) {
  try {
    openAndRead(path);
  } catch (const pvr::Error& e) {
    return e.code();
  }
  return pvr::ErrorCode::kInternal;
}

}  // namespace

TEST_CASE("a missing file says so, naming it", "[io]") {
  const std::string dir = scratchDir("err_missing");
  for (const char* name : {"/nope.json", "/nope.raw", "/nope.nrrd", "/nope.nhdr", "/nope.nii", "/nope.nii.gz"}) {
    const std::string path = dir + name;
    REQUIRE_THROWS_WITH(openAndRead(path), StartsWith(path) && Contains("no such file"));
    CHECK(errorCodeOf(path) == pvr::ErrorCode::kIo);
  }
}

TEST_CASE("a missing data file or sidecar names the file that is missing", "[io]") {
  const std::string dir = scratchDir("err_missing_data");
  const TestVolume v = testVolume(ScalarType::kUInt8);
  const std::string json = writeRawJson(dir, "v", v, false);
  fs::remove(dir + "/v.raw");
  REQUIRE_THROWS_WITH(openAndRead(json), StartsWith(dir + "/v.raw: no such file") &&
                                             Contains("(data file of " + json + ")"));

  writeBytes(dir + "/lonely.raw", voxelData(v, false));
  REQUIRE_THROWS_WITH(openAndRead(dir + "/lonely.raw"),
                      StartsWith(dir + "/lonely.raw") && Contains("no JSON sidecar"));

  NrrdOptions o;
  o.attached = false;
  const std::string nhdr = writeNrrd(dir, "d", v, o);
  fs::remove(dir + "/d.raw");
  REQUIRE_THROWS_WITH(openAndRead(nhdr),
                      StartsWith(dir + "/d.raw: no such file") && Contains("(data file of " + nhdr + ")"));
}

TEST_CASE("an unknown extension lists the supported ones", "[io]") {
  const std::string dir = scratchDir("err_extension");
  writeBytes(dir + "/v.vtk", textBytes("# vtk DataFile Version 3.0\n"));
  REQUIRE_THROWS_WITH(openAndRead(dir + "/v.vtk"),
                      StartsWith(dir + "/v.vtk") && Contains(".nrrd .nhdr") && Contains(".nii .nii.gz") &&
                          Contains(".json .raw"));
}

TEST_CASE("truncated data is reported with the byte counts, in every format", "[io]") {
  const std::string dir = scratchDir("err_truncated");
  const TestVolume v = testVolume(ScalarType::kInt16);  // 9x7x5 int16 = 630 bytes

  writeRawJson(dir, "t", v, false);
  truncateFile(dir + "/t.raw", 10);
  REQUIRE_THROWS_WITH(openAndRead(dir + "/t.json"),
                      StartsWith(dir + "/t.raw: file has 620 bytes, header needs 630 (9x7x5 int16)"));

  NrrdOptions o;
  const std::string nrrd = writeNrrd(dir, "a", v, o);
  truncateFile(nrrd, 1);
  REQUIRE_THROWS_WITH(openAndRead(nrrd), StartsWith(nrrd) && Contains("bytes, header needs") &&
                                             Contains("bytes before the voxels + 9x7x5 int16"));

  o.gzip = true;
  const std::string gz = writeNrrd(dir, "g", v, o);
  truncateFile(gz, 40);
  REQUIRE_THROWS_WITH(openAndRead(gz), StartsWith(gz) && Contains("truncated"));

  o.attached = false;
  const std::string nhdrGz = writeNrrd(dir, "dg", v, o);
  truncateFile(dir + "/dg.raw.gz", 40);
  REQUIRE_THROWS_WITH(openAndRead(nhdrGz), StartsWith(dir + "/dg.raw.gz") && Contains("truncated"));

  const std::string nii = writeNifti(dir, "n", v, {});
  truncateFile(nii, 2);
  REQUIRE_THROWS_WITH(openAndRead(nii), StartsWith(nii) && Contains("file has 980 bytes, header needs 982"));

  NiftiOptions zo;
  zo.gzip = true;
  const std::string niiGz = writeNifti(dir, "z", v, zo);
  truncateFile(niiGz, 30);
  REQUIRE_THROWS_WITH(openAndRead(niiGz), StartsWith(niiGz) && Contains("truncated"));

  // A file too short for a NIfTI header at all.
  writeBytes(dir + "/short.nii", std::vector<std::byte>(100));
  REQUIRE_THROWS_WITH(openAndRead(dir + "/short.nii"),
                      StartsWith(dir + "/short.nii") && Contains("file has 100 bytes, a NIfTI-1 header needs 348"));
}

TEST_CASE("dims that do not match the byte count are refused, larger or smaller", "[io]") {
  const std::string dir = scratchDir("err_dims");
  const TestVolume v = testVolume(ScalarType::kUInt16);

  writeRawJson(dir, "big", v, false);
  replaceInFile(dir + "/big.json", "\"dims\": [9, 7, 5]", "\"dims\": [9, 7, 6]");
  REQUIRE_THROWS_WITH(openAndRead(dir + "/big.json"),
                      StartsWith(dir + "/big.raw") && Contains("file has 630 bytes, header needs 756 (9x7x6 uint16)"));
  writeRawJson(dir, "small", v, false);
  replaceInFile(dir + "/small.json", "\"dims\": [9, 7, 5]", "\"dims\": [9, 7, 4]");
  REQUIRE_THROWS_WITH(openAndRead(dir + "/small.json"),
                      Contains("file has 630 bytes, header needs 504 (9x7x4 uint16)"));

  NrrdOptions o;
  o.attached = false;
  writeNrrd(dir, "n", v, o);
  replaceInFile(dir + "/n.nhdr", "sizes: 9 7 5", "sizes: 9 8 5");
  REQUIRE_THROWS_WITH(openAndRead(dir + "/n.nhdr"), StartsWith(dir + "/n.raw") && Contains("needs 720 (9x8x5 uint16)"));

  o.gzip = true;
  writeNrrd(dir, "g", v, o);
  replaceInFile(dir + "/g.nhdr", "sizes: 9 7 5", "sizes: 9 7 4");
  REQUIRE_THROWS_WITH(openAndRead(dir + "/g.nhdr"),
                      Contains("gzip data decodes to 630 bytes, header needs 504 (9x7x4 uint16)"));

  // NIfTI: a header claiming a larger volume than the data holds.
  nifti_1_header h = niftiHeader(v, {});
  h.dim[3] = 50;
  writeBytes(dir + "/n.nii", niftiBytes(h, v, false));
  REQUIRE_THROWS_WITH(openAndRead(dir + "/n.nii"), StartsWith(dir + "/n.nii") && Contains("9x7x50 uint16)"));
}

TEST_CASE("an unknown or unsupported scalar type is named", "[io]") {
  const std::string dir = scratchDir("err_type");
  const TestVolume v = testVolume(ScalarType::kFloat32);
  writeRawJson(dir, "j", v, false);
  replaceInFile(dir + "/j.json", "\"float32\"", "\"complex64\"");
  REQUIRE_THROWS_WITH(openAndRead(dir + "/j.json"), StartsWith(dir + "/j.json") && Contains("unknown scalar type 'complex64'"));

  NrrdOptions o;
  o.typeName = "double";
  const std::string nrrd = writeNrrd(dir, "n", v, o);
  REQUIRE_THROWS_WITH(openAndRead(nrrd), StartsWith(nrrd) && Contains("unknown scalar type 'double'"));

  NiftiOptions no;
  no.datatype = DT_FLOAT64;
  const std::string nii = writeNifti(dir, "n", v, no);
  REQUIRE_THROWS_WITH(openAndRead(nii), StartsWith(nii) && Contains("datatype FLOAT64 is not supported"));
}

TEST_CASE("unreadable or garbled headers are refused with the reason", "[io]") {
  const std::string dir = scratchDir("err_garbled");
  const TestVolume v = testVolume(ScalarType::kUInt8);

  SECTION("json") {
    writeRawJson(dir, "j", v, false);
    replaceInFile(dir + "/j.json", "\"dtype\":", "\"dtype\" ");
    REQUIRE_THROWS_WITH(openAndRead(dir + "/j.json"), StartsWith(dir + "/j.json") && Contains("not valid JSON"));
    writeBytes(dir + "/k.json", textBytes(R"({"dims": [9, 7], "dtype": "uint8", "spacing": [1, 1, 1]})"));
    REQUIRE_THROWS_WITH(openAndRead(dir + "/k.json"), Contains("'dims' must be 3 positive integers"));
    writeBytes(dir + "/l.json", textBytes(R"({"dims": [9, 7, 5], "dtype": "uint8"})"));
    REQUIRE_THROWS_WITH(openAndRead(dir + "/l.json"), Contains("no 'spacing' key"));
    writeBytes(dir + "/m.json", textBytes(R"({"dims": [9, 7, 5], "dtype": "uint8", "spacing": [1, 0, 1]})"));
    REQUIRE_THROWS_WITH(openAndRead(dir + "/m.json"), StartsWith(dir + "/m.json") && Contains("spacing 1 must be finite and positive"));
    writeBytes(dir + "/n.json", textBytes("[1, 2, 3]"));
    REQUIRE_THROWS_WITH(openAndRead(dir + "/n.json"), Contains("not a JSON object"));
  }
  SECTION("nrrd") {
    // One edit of a good header each, and what the message must say.
    struct Edit {
      const char* from;
      const char* to;
      const char* says;
    };
    const Edit edits[] = {
        {"NRRD0004", "NRRX0004", "not a NRRD file"},
        {"dimension: 3", "dimension 3", "line 4: expected 'field: value'"},
        {"sizes:", "sizez:", "unknown field 'sizez'"},
        {"sizes: 9 7 5", "sizes: 9 7", "sizes has 2 values, need 3"},
        {"sizes: 9 7 5", "sizes: 9 seven 5", "sizes: 'seven' is not a number"},
        {"encoding: raw", "encoding: bzip2", "encoding 'bzip2' is not supported"},
        {"dimension: 3", "dimension: 4", "only 3D volumes"},
        {"kinds:", "sizes: 1 1 1\nkinds:", "field 'sizes' appears twice"},
        {"kinds:", "space directions: (1,0,0) none (0,0,1)\nkinds:", "axis 1 is 'none'"},
    };
    for (const Edit& e : edits) {
      INFO(e.from << " -> " << e.to);
      const std::string nrrd = writeNrrd(dir, "n", v, {});
      replaceInFile(nrrd, e.from, e.to);
      REQUIRE_THROWS_WITH(openAndRead(nrrd), StartsWith(nrrd) && Contains(e.says));
    }
    writeBytes(dir + "/empty.nrrd", {});
    REQUIRE_THROWS_WITH(openAndRead(dir + "/empty.nrrd"), StartsWith(dir + "/empty.nrrd") && Contains("empty"));
    // Random bytes behind a valid magic line.
    std::vector<std::byte> noise = textBytes("NRRD0004\n");
    for (int i = 0; i < 3000; ++i) noise.push_back(std::byte((i * 7919 + 13) % 251));
    writeBytes(dir + "/noise.nrrd", noise);
    REQUIRE_THROWS_AS(openAndRead(dir + "/noise.nrrd"), pvr::Error);
  }
  SECTION("nrrd multi-byte data without endian") {
    const std::string nrrd = writeNrrd(dir, "e", testVolume(ScalarType::kInt16), {});
    replaceInFile(nrrd, "endian: little\n", "");
    REQUIRE_THROWS_WITH(openAndRead(nrrd), StartsWith(nrrd) && Contains("no 'endian' field"));
  }
  SECTION("nrrd gzip that is not gzip") {
    NrrdOptions o;
    o.attached = false;
    o.gzip = true;
    const std::string nhdr = writeNrrd(dir, "z", v, o);
    writeBytes(dir + "/z.raw.gz", voxelData(v, false));
    REQUIRE_THROWS_WITH(openAndRead(nhdr), StartsWith(dir + "/z.raw.gz") && Contains("corrupt gzip data"));
  }
  SECTION("nifti") {
    std::vector<std::byte> noise;
    for (int i = 0; i < 2000; ++i) noise.push_back(std::byte((i * 7919 + 13) % 251));
    writeBytes(dir + "/noise.nii", noise);
    REQUIRE_THROWS_WITH(openAndRead(dir + "/noise.nii"),
                        StartsWith(dir + "/noise.nii") && Contains("not a NIfTI-1 file"));
    writeBytes(dir + "/noise.nii.gz", gzipBytes(noise));
    REQUIRE_THROWS_WITH(openAndRead(dir + "/noise.nii.gz"), Contains("not a NIfTI-1 file"));
    writeBytes(dir + "/plain.nii.gz", noise);
    REQUIRE_THROWS_WITH(openAndRead(dir + "/plain.nii.gz"), Contains("corrupt gzip data"));
    nifti_1_header h = niftiHeader(v, {});
    std::memcpy(h.magic, "xyz", 4);
    writeBytes(dir + "/magic.nii", niftiBytes(h, v, false));
    REQUIRE_THROWS_WITH(openAndRead(dir + "/magic.nii"), Contains("no NIfTI-1 magic"));
    // 4-D is a time series (volume_series_test.cpp); 5-D is refused.
    h = niftiHeader(v, {});
    h.dim[0] = 5;
    h.dim[5] = 3;
    writeBytes(dir + "/5d.nii", niftiBytes(h, v, false));
    REQUIRE_THROWS_WITH(openAndRead(dir + "/5d.nii"), Contains("only 3D volumes and 4D time series"));
  }
}

TEST_CASE("absurd sizes in a header fail before anything is allocated", "[io]") {
  // Each of these would ask for petabytes if a size were trusted.
  const std::string dir = scratchDir("err_absurd");
  writeBytes(dir + "/a.json",
             textBytes(R"({"dims": [1000000000, 1000000000, 1000000000], "dtype": "float32", "spacing": [1, 1, 1]})"));
  writeBytes(dir + "/a.raw", std::vector<std::byte>(16));
  REQUIRE_THROWS_WITH(openAndRead(dir + "/a.json"), Contains("too large"));

  writeBytes(dir + "/b.nrrd", textBytes("NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\n"
                                        "encoding: raw\nendian: little\n\n0123456789"));
  REQUIRE_THROWS_WITH(openAndRead(dir + "/b.nrrd"),
                      StartsWith(dir + "/b.nrrd") && Contains("file has 102 bytes, header needs 4000000000000092"));

  writeBytes(dir + "/c.nrrd", textBytes("NRRD0004\ntype: float\ndimension: 3\nsizes: 1 -5 1\n"
                                        "encoding: raw\nendian: little\n\n"));
  REQUIRE_THROWS_WITH(openAndRead(dir + "/c.nrrd"), Contains("sizes is -5, must be >= 1"));

  NrrdOptions o;
  o.gzip = true;
  const TestVolume v = testVolume(ScalarType::kUInt8);
  const std::string gz = writeNrrd(dir, "g", v, o);
  replaceInFile(gz, "sizes: 9 7 5", "sizes: 90000 70000 50000");
  REQUIRE_THROWS_WITH(openAndRead(gz), Contains("gzip data decodes to 315 bytes"));
}

TEST_CASE("reading a box outside the grid names the file", "[io]") {
  const std::string dir = scratchDir("err_box");
  const TestVolume v = testVolume(ScalarType::kUInt8);
  const std::string json = writeRawJson(dir, "v", v, false);
  const auto src = openVolumeFile(json);
  const NodeBox outside{{0, 0, 0}, {9, 6, 4}};
  REQUIRE_THROWS_WITH(src->readBox(outside, outside), StartsWith(dir + "/v.raw") && Contains("lie in the grid"));
  const NodeBox owned{{0, 0, 0}, {3, 3, 3}};
  const NodeBox stored{{1, 1, 1}, {3, 3, 3}};
  REQUIRE_THROWS_AS(src->readBox(owned, stored), pvr::Error);
}
