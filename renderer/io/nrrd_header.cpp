#include "nrrd_header.h"

#include <charconv>
#include <cmath>
#include <set>
#include <vector>

#include "source_util.h"

namespace pvr::core {

namespace {

struct ParseState {
  explicit ParseState(const std::string& p) : path(p) {}

  const std::string& path;
  int line = 0;
  NrrdHeader header;
  std::set<std::string, std::less<>> seen;
  int dimension = 0;
  bool haveType = false, haveSizes = false, haveEncoding = false;
  std::optional<Vec3> spacings, directionLengths, spaceOrigin, axisMins;

  [[noreturn]] void fail(ErrorCode code, const std::string& what) const {
    failAt(code, path, "line " + std::to_string(line) + ": " + what);
  }
};

std::string_view trim(std::string_view s) {
  const std::size_t b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> out;
  for (std::size_t pos = 0;;) {
    const std::size_t b = s.find_first_not_of(" \t", pos);
    if (b == std::string_view::npos) return out;
    const std::size_t e = s.find_first_of(" \t", b);
    out.push_back(s.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b));
    if (e == std::string_view::npos) return out;
    pos = e;
  }
}

template <typename T>
T number(const ParseState& st, std::string_view token, std::string_view field) {
  std::string_view t = trim(token);
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);  // from_chars refuses a leading '+'
  T value{};
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec != std::errc() || end != t.data() + t.size() || t.empty())
    st.fail(ErrorCode::kBadFile, std::string(field) + ": '" + std::string(token) + "' is not a number");
  return value;
}

// Exactly three numbers, one per axis of a 3D volume.
Vec3 threeNumbers(const ParseState& st, std::string_view value, std::string_view field) {
  const std::vector<std::string_view> w = words(value);
  if (w.size() != 3)
    st.fail(ErrorCode::kBadFile, std::string(field) + " has " + std::to_string(w.size()) +
                                     " values, need 3");
  return {number<double>(st, w[0], field), number<double>(st, w[1], field),
          number<double>(st, w[2], field)};
}

// "(a,b,c)" vectors separated by spaces; "none" marks a non-spatial axis.
std::vector<std::optional<Vec3>> vectors(const ParseState& st, std::string_view value,
                                         std::string_view field) {
  std::vector<std::optional<Vec3>> out;
  std::size_t pos = 0;
  while ((pos = value.find_first_not_of(" \t", pos)) != std::string_view::npos) {
    if (value.substr(pos, 4) == "none") {
      out.emplace_back();
      pos += 4;
      continue;
    }
    const std::size_t close = value.find(')', pos);
    if (value[pos] != '(' || close == std::string_view::npos)
      st.fail(ErrorCode::kBadFile, std::string(field) + ": expected '(x,y,z)' or 'none' at '" +
                                       std::string(value.substr(pos)) + "'");
    std::string inner(value.substr(pos + 1, close - pos - 1));
    for (char& c : inner)
      if (c == ',') c = ' ';
    out.emplace_back(threeNumbers(st, inner, field));
    pos = close + 1;
  }
  return out;
}

std::int64_t integer(const ParseState& st, std::string_view value, std::string_view field,
                     std::int64_t min) {
  const auto v = number<std::int64_t>(st, value, field);
  if (v < min)
    st.fail(ErrorCode::kBadFile, std::string(field) + " is " + std::to_string(v) +
                                     ", must be >= " + std::to_string(min));
  return v;
}

// NRRD type names parseScalarType does not know; the rest it takes as is.
std::string_view canonicalType(std::string_view t) {
  if (t == "short int" || t == "signed short int") return "int16";
  if (t == "unsigned short int") return "uint16";
  return t;
}

// Step: one handler per field, dispatched from a table.
using FieldParser = void (*)(ParseState&, std::string_view);

void parseType(ParseState& st, std::string_view v) {
  st.header.type = parseScalarType(canonicalType(v), st.path);
  st.haveType = true;
}
void parseDimension(ParseState& st, std::string_view v) {
  st.dimension = int(integer(st, v, "dimension", 1));
  if (st.dimension != 3)
    st.fail(ErrorCode::kUnsupported,
            "dimension is " + std::to_string(st.dimension) + ", only 3D volumes are supported");
}
void parseSizes(ParseState& st, std::string_view v) {
  const std::vector<std::string_view> w = words(v);
  if (w.size() != 3)
    st.fail(ErrorCode::kBadFile, "sizes has " + std::to_string(w.size()) + " values, need 3");
  for (int a = 0; a < 3; ++a) st.header.grid.dims[a] = integer(st, w[a], "sizes", 1);
  st.haveSizes = true;
}
void parseSpacings(ParseState& st, std::string_view v) { st.spacings = threeNumbers(st, v, "spacings"); }
void parseAxisMins(ParseState& st, std::string_view v) { st.axisMins = threeNumbers(st, v, "axis mins"); }
void parseSpaceDirections(ParseState& st, std::string_view v) {
  const auto dirs = vectors(st, v, "space directions");
  if (dirs.size() != 3)
    st.fail(ErrorCode::kBadFile, "space directions has " + std::to_string(dirs.size()) +
                                     " entries, need 3");
  // Lengths are the spacing; the directions themselves orient the grid (nrrd.cpp).
  Vec3 lengths;
  std::array<Vec3, 3> directions;
  for (int a = 0; a < 3; ++a) {
    if (!dirs[a]) st.fail(ErrorCode::kUnsupported, "space directions: axis " + std::to_string(a) + " is 'none'");
    lengths[a] = length(*dirs[a]);
    directions[std::size_t(a)] = *dirs[a];
  }
  st.directionLengths = lengths;
  st.header.spaceDirections = directions;
}
void parseSpaceOrigin(ParseState& st, std::string_view v) {
  const auto origin = vectors(st, v, "space origin");
  if (origin.size() != 1 || !origin[0]) st.fail(ErrorCode::kBadFile, "space origin must be one '(x,y,z)'");
  st.spaceOrigin = *origin[0];
}
void parseEncoding(ParseState& st, std::string_view v) {
  if (v == "raw")
    st.header.encoding = NrrdEncoding::kRaw;
  else if (v == "gzip" || v == "gz")
    st.header.encoding = NrrdEncoding::kGzip;
  else
    st.fail(ErrorCode::kUnsupported, "encoding '" + std::string(v) + "' is not supported (raw, gzip)");
  st.haveEncoding = true;
}
void parseEndian(ParseState& st, std::string_view v) {
  if (v != "little" && v != "big")
    st.fail(ErrorCode::kBadFile, "endian must be 'little' or 'big', got '" + std::string(v) + "'");
  st.header.bigEndian = v == "big";
}
void parseByteSkip(ParseState& st, std::string_view v) { st.header.byteSkip = integer(st, v, "byte skip", -1); }
void parseLineSkip(ParseState& st, std::string_view v) { st.header.lineSkip = integer(st, v, "line skip", 0); }
void parseDataFile(ParseState& st, std::string_view v) {
  if (v.empty() || v.starts_with("LIST") || v.find('%') != std::string_view::npos)
    st.fail(ErrorCode::kUnsupported, "data file '" + std::string(v) + "': only a single data file is supported");
  st.header.dataFile = std::string(v);
}
void ignoreField(ParseState&, std::string_view) {}

struct Field {
  std::string_view name;
  FieldParser parse;
};
constexpr Field kFields[] = {
    {"type", parseType}, {"dimension", parseDimension}, {"sizes", parseSizes},
    {"spacings", parseSpacings}, {"axis mins", parseAxisMins}, {"axismins", parseAxisMins},
    {"space directions", parseSpaceDirections}, {"space origin", parseSpaceOrigin},
    {"encoding", parseEncoding}, {"endian", parseEndian},
    {"byte skip", parseByteSkip}, {"byteskip", parseByteSkip},
    {"line skip", parseLineSkip}, {"lineskip", parseLineSkip},
    {"data file", parseDataFile}, {"datafile", parseDataFile},
    // Meaningful to NRRD but not to a scalar volume on an axis-aligned grid.
    {"content", ignoreField}, {"kinds", ignoreField}, {"centers", ignoreField},
    {"centerings", ignoreField}, {"labels", ignoreField}, {"units", ignoreField},
    {"space", ignoreField}, {"space dimension", ignoreField}, {"space units", ignoreField},
    {"measurement frame", ignoreField}, {"thicknesses", ignoreField}, {"axis maxs", ignoreField},
    {"axismaxs", ignoreField}, {"min", ignoreField}, {"max", ignoreField},
    {"old min", ignoreField}, {"oldmin", ignoreField}, {"old max", ignoreField},
    {"oldmax", ignoreField}, {"sample units", ignoreField}, {"sampleunits", ignoreField},
    {"number", ignoreField}, {"block size", ignoreField}, {"blocksize", ignoreField},
};

void parseLine(ParseState& st, std::string_view text) {
  if (text.front() == '#') return;
  // "key:=value" pairs are free-form metadata.
  const std::size_t kv = text.find(":=");
  const std::size_t colon = text.find(": ");
  if (kv != std::string_view::npos && (colon == std::string_view::npos || kv < colon)) return;
  const bool bare = colon == std::string_view::npos && text.back() == ':';
  if (colon == std::string_view::npos && !bare)
    st.fail(ErrorCode::kBadFile, "expected 'field: value', got " + quoteForMessage(text));
  const std::string_view name = bare ? text.substr(0, text.size() - 1) : text.substr(0, colon);
  const std::string_view value = bare ? std::string_view() : trim(text.substr(colon + 2));
  for (const Field& f : kFields) {
    if (f.name != name) continue;
    if (!st.seen.emplace(name).second)
      st.fail(ErrorCode::kBadFile, "field '" + std::string(name) + "' appears twice");
    f.parse(st, value);
    return;
  }
  st.fail(ErrorCode::kBadFile, "unknown field " + quoteForMessage(name));
}

void finish(ParseState& st) {
  NrrdHeader& h = st.header;
  const auto require = [&](bool have, const char* field) {
    if (!have) failAt(ErrorCode::kBadFile, st.path, std::string("header has no '") + field + "' field");
  };
  require(st.haveType, "type");
  require(st.dimension != 0, "dimension");
  require(st.haveSizes, "sizes");
  require(st.haveEncoding, "encoding");
  if (scalarSize(h.type) > 1 && !h.bigEndian)
    failAt(ErrorCode::kBadFile, st.path,
           "header has no 'endian' field, needed for " + std::string(scalarName(h.type)) + " data");
  // Space directions win over spacings, as in Teem; a "nan" spacing fails grid validation later.
  h.grid.spacing = st.directionLengths.value_or(st.spacings.value_or(Vec3{1, 1, 1}));
  if (st.spaceOrigin)
    h.grid.origin = *st.spaceOrigin;
  else if (st.axisMins && std::isfinite(st.axisMins->x + st.axisMins->y + st.axisMins->z))
    h.grid.origin = *st.axisMins;
}

}  // namespace

NrrdHeader parseNrrdHeader(std::string_view text, bool complete, const std::string& path) {
  ParseState st(path);
  std::size_t pos = 0;
  while (pos < text.size()) {
    // Step: cut the next line ("\n" or "\r\n" ended).
    const std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos && !complete)
      failAt(ErrorCode::kBadFile, path,
             "no blank line ends the header within its first " + std::to_string(text.size()) + " bytes");
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    ++st.line;

    // Step: the magic, then fields until the blank line that precedes attached data.
    if (st.line == 1) {
      if (!(line.size() == 8 && line.starts_with("NRRD000") && line[7] >= '1' && line[7] <= '5'))
        failAt(ErrorCode::kBadFile, path,
               "not a NRRD file: first line is " + quoteForMessage(line) + ", expected NRRD0001..NRRD0005");
      continue;
    }
    if (line.empty()) {
      st.header.dataStart = pos;
      break;
    }
    parseLine(st, line);
  }
  if (st.line == 0) failAt(ErrorCode::kBadFile, path, "file is empty, not a NRRD header");
  if (!st.header.dataStart && !complete)
    failAt(ErrorCode::kBadFile, path, "header continues past its first " + std::to_string(text.size()) + " bytes");
  finish(st);
  return st.header;
}

}  // namespace pvr::core
