#include "series.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "source_util.h"

namespace pvr::core {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Steps may come from different formats: NIfTI stores spacing and origin
// as float32, a JSON sidecar as double. Spacings agree to a relative 1e-5,
// origins to 1e-4 of the smallest spacing (a ten-thousandth of a voxel).
constexpr double kSpacingTolerance = 1e-5;
constexpr double kOriginTolerance = 1e-4;

std::string numberText(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string vecText(Vec3 v) { return numberText(v.x) + " " + numberText(v.y) + " " + numberText(v.z); }

std::string dimsText(IVec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

std::string stepText(std::int64_t k, std::string_view label) {
  return "step " + std::to_string(k) + " '" + std::string(label) + "'";
}

// What makes `g` differ from step 0's grid `g0`, or empty when they agree.
std::string gridDifference(const GridGeometry& g, const GridGeometry& g0) {
  if (g.dims != g0.dims) return "dims " + dimsText(g.dims) + " differ from step 0's " + dimsText(g0.dims);
  const double smallest = std::min({g0.spacing.x, g0.spacing.y, g0.spacing.z});
  for (int a = 0; a < 3; ++a)
    if (std::fabs(g.spacing[a] - g0.spacing[a]) > kSpacingTolerance * std::fabs(g0.spacing[a]))
      return "spacing " + vecText(g.spacing) + " differs from step 0's " + vecText(g0.spacing);
  for (int a = 0; a < 3; ++a)
    if (std::fabs(g.origin[a] - g0.origin[a]) > kOriginTolerance * smallest)
      return "origin " + vecText(g.origin) + " differs from step 0's " + vecText(g0.origin);
  return {};
}

class SeriesSource final : public VolumeSource {
 public:
  SeriesSource(std::string name, std::vector<SeriesStep> steps) : name_(std::move(name)), steps_(std::move(steps)) {}

  const GridGeometry& grid() const override { return steps_[0].volume->grid(); }
  ScalarType type() const override { return steps_[0].volume->type(); }
  // A caller that reads part of the series reads part of every step.
  bool canReadPartially() const override {
    for (const SeriesStep& s : steps_)
      if (!s.volume->canReadPartially()) return false;
    return true;
  }
  Brick readBox(const NodeBox& owned, const NodeBox& stored) const override {
    return steps_[0].volume->readBox(owned, stored);
  }
  std::string describe() const override {
    return name_ + ": " + std::to_string(steps_.size()) + " steps of " + shapeText(grid(), type());
  }
  void setFineCounts(bool on) override {
    for (SeriesStep& s : steps_) s.volume->setFineCounts(on);
  }
  // The steps share step 0's grid, so they share its orientation too.
  std::string caveat() const override { return steps_[0].volume->caveat(); }

  int steps() const override { return int(steps_.size()); }
  double stepTime(int k) const override { return at(k).time; }
  const VolumeSource& step(int k) const override { return *at(k).volume; }

  std::vector<std::string> files() const {
    std::vector<std::string> out;
    for (const SeriesStep& s : steps_)
      if (!s.file.empty()) out.push_back(s.file);
    return out;
  }

 private:
  const SeriesStep& at(int k) const {
    if (k < 0 || std::size_t(k) >= steps_.size())
      failAt(ErrorCode::kInvalidArgument, name_,
             "no step " + std::to_string(k) + ": the series has " + std::to_string(steps_.size()) + " steps (0.." +
                 std::to_string(steps_.size() - 1) + ")");
    return steps_[std::size_t(k)];
  }

  std::string name_;
  std::vector<SeriesStep> steps_;
};

std::string realPathOf(const std::string& path) {
  char buf[PATH_MAX];
  return ::realpath(path.c_str(), buf) ? std::string(buf) : std::string();
}

const json& requiredKey(const json& doc, const char* key, std::string_view where) {
  const auto it = doc.find(key);
  if (it == doc.end()) failAt(ErrorCode::kBadFile, where, std::string("no '") + key + "' key");
  return *it;
}

std::int64_t integerKey(const json& v, const char* key, std::int64_t lo, std::int64_t hi, std::string_view where) {
  if (!v.is_number_integer() || v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi ||
      (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(hi)))
    failAt(ErrorCode::kBadFile, where,
           std::string("'") + key + "' must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
               ", got " + v.dump());
  return v.get<std::int64_t>();
}

double numberKey(const json& v, const std::string& key, std::string_view where) {
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    failAt(ErrorCode::kBadFile, where, "'" + key + "' must be a finite number, got " + v.dump());
  return v.get<double>();
}

}  // namespace

std::unique_ptr<VolumeSource> makeSeries(std::string where, std::string name, std::vector<SeriesStep> steps) {
  if (steps.empty()) failAt(ErrorCode::kBadFile, where, "the series has no steps");
  const GridGeometry& g0 = steps[0].volume->grid();
  const ScalarType t0 = steps[0].volume->type();
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const SeriesStep& s = steps[k];
    const auto fail = [&](const std::string& what) {
      failAt(ErrorCode::kBadFile, where, stepText(std::int64_t(k), s.label) + ": " + what);
    };
    if (s.volume->steps() != 1)
      fail("is itself a series of " + std::to_string(s.volume->steps()) + " steps; a step is one volume");
    if (const std::string d = gridDifference(s.volume->grid(), g0); !d.empty()) fail(d);
    if (s.volume->type() != t0)
      fail("scalar type " + std::string(scalarName(s.volume->type())) + " differs from step 0's " +
           std::string(scalarName(t0)));
    if (!std::isfinite(s.time)) fail("time " + numberText(s.time) + " is not finite");
    if (k > 0 && !(s.time > steps[k - 1].time))
      fail("time " + numberText(s.time) + " does not follow step " + std::to_string(k - 1) + "'s " +
           numberText(steps[k - 1].time) + "; times must increase");
  }
  return std::make_unique<SeriesSource>(std::move(name), std::move(steps));
}

std::unique_ptr<VolumeSource> openStep(std::string_view where, std::int64_t k, std::string_view label,
                                       const std::string& file,
                                       const std::function<std::unique_ptr<VolumeSource>()>& open) {
  try {
    return open();
  } catch (const Error& e) {
    // The opener's message starts with the file's path, which the step's
    // label already names.
    std::string what = e.what();
    if (!file.empty() && what.rfind(file + ": ", 0) == 0) what.erase(0, file.size() + 2);
    throw Error(e.code(), std::string(where) + ": " + stepText(k, label) + ": " + what);
  }
}

std::string stepFilePath(const std::string& sidecarPath, const std::string& entry, std::string_view where,
                         std::int64_t k) {
  const auto refuse = [&](const std::string& why) {
    failAt(ErrorCode::kBadFile, where, stepText(k, entry) + ": " + why);
  };
  const fs::path named(entry);
  if (entry.empty()) refuse("the file name is empty");
  if (named.is_absolute()) refuse("absolute paths are refused; name files relative to the sidecar's directory");
  for (const fs::path& part : named)
    if (part == "..") refuse("'..' leaves the sidecar's directory");
  const fs::path dir = fs::path(sidecarPath).parent_path();
  const std::string path = (dir / named).string();
  const std::string real = realPathOf(path);
  if (real.empty()) return path;  // missing: the opener says so
  const std::string root = realPathOf(dir.empty() ? "." : dir.string());
  if (root.empty() || real.size() <= root.size() || real.compare(0, root.size(), root) != 0 ||
      (root != "/" && real[root.size()] != '/'))
    refuse("resolves to " + real + ", outside the sidecar's directory");
  return path;
}

StepPattern::StepPattern(const std::string& pattern, std::string_view where) {
  const auto refuse = [&](const std::string& why) {
    failAt(ErrorCode::kBadFile, where, "'pattern' " + quoteForMessage(pattern, 80) + ": " + why);
  };
  bool converted = false;
  std::string* out = &prefix_;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      *out += pattern[i];
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      *out += '%';
      ++i;
      continue;
    }
    // Exactly "%d" or "%0Nd".
    std::size_t j = i + 1;
    int width = 0;
    if (j < pattern.size() && pattern[j] == '0') {
      ++j;
      if (j >= pattern.size() || pattern[j] < '1' || pattern[j] > '9')
        refuse("a width is %0Nd with N in 1..9");
      width = pattern[j++] - '0';
      if (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9') refuse("a width over 9 is refused");
    }
    if (j >= pattern.size() || pattern[j] != 'd')
      refuse("only %d or %0Nd (N in 1..9) may be used, found '" + pattern.substr(i, j + 1 - i) + "'");
    if (converted) refuse("holds more than one conversion; exactly one %d or %0Nd");
    converted = true;
    width_ = width;
    out = &suffix_;
    i = j;
  }
  if (!converted) refuse("holds no %d or %0Nd for the step number");
}

std::string StepPattern::fileFor(std::int64_t index) const {
  std::string digits = std::to_string(index);
  if (std::int64_t(digits.size()) < width_) digits.insert(0, std::size_t(width_) - digits.size(), '0');
  return prefix_ + digits + suffix_;
}

std::vector<PatternStep> patternSteps(const json& doc, std::string_view where) {
  const json& p = requiredKey(doc, "pattern", where);
  if (!p.is_string()) failAt(ErrorCode::kBadFile, where, "'pattern' must be a string, got " + p.dump());
  const StepPattern pattern(p.get<std::string>(), where);
  const std::int64_t count = integerKey(requiredKey(doc, "steps", where), "steps", 1, kMaxSeriesSteps, where);
  std::int64_t first = 0;
  if (const auto it = doc.find("first"); it != doc.end())
    first = integerKey(*it, "first", 0, std::int64_t(INT32_MAX) - count + 1, where);

  // Times: listed, or evenly spaced from 0.
  const auto times = doc.find("times");
  const auto timeStep = doc.find("time_step");
  if (times != doc.end() && timeStep != doc.end())
    failAt(ErrorCode::kBadFile, where, "give 'times' or 'time_step', not both");
  if (times != doc.end() && (!times->is_array() || std::int64_t(times->size()) != count))
    failAt(ErrorCode::kBadFile, where,
           "'times' must be an array of " + std::to_string(count) + " numbers, one per step");
  const double dt = timeStep != doc.end() ? numberKey(*timeStep, "time_step", where) : 1.0;
  if (!(dt > 0)) failAt(ErrorCode::kBadFile, where, "'time_step' must be > 0, got " + numberText(dt));

  std::vector<PatternStep> steps(static_cast<std::size_t>(count));
  for (std::int64_t k = 0; k < count; ++k) {
    PatternStep& s = steps[std::size_t(k)];
    s.file = pattern.fileFor(first + k);
    s.time = times != doc.end() ? numberKey((*times)[std::size_t(k)], "times[" + std::to_string(k) + "]", where)
                                : double(k) * dt;
  }
  return steps;
}

std::vector<std::unique_ptr<VolumeSource>> openPackedSteps(const std::string& name, const GridGeometry& grid,
                                                           ScalarType type, const RawLayout& layout,
                                                           std::int64_t count, SizeRule rule) {
  const std::string where = layout.headerPath.empty() ? layout.dataPath : layout.headerPath;
  if (count < 1 || count > kMaxSeriesSteps)
    failAt(ErrorCode::kBadFile, where,
           std::to_string(count) + " time steps; a series has 1.." + std::to_string(kMaxSeriesSteps));
  // The steps together are one volume `count` times as deep: checking its
  // size checks every step's at once (one trailer look for gzip, not one
  // decode per step).
  const std::uint64_t stepBytes = voxelBytes(grid, type, where);
  GridGeometry all = grid;
  all.dims.z = grid.dims.z * count;  // both below 2^31: no overflow; openRawVolume bounds the product
  try {
    openRawVolume(name, all, type, layout, rule);
  } catch (const Error& e) {
    throw Error(e.code(), std::string(e.what()) + " (" + std::to_string(count) + " time steps of " +
                              shapeText(grid, type) + ")");
  }
  std::vector<std::unique_ptr<VolumeSource>> steps;
  for (std::int64_t k = 0; k < count; ++k) {
    RawLayout step = layout;
    step.offset = layout.offset + std::uint64_t(k) * stepBytes;
    steps.push_back(rawVolumeSource(name + " step " + std::to_string(k), grid, type, std::move(step)));
  }
  return steps;
}

std::vector<std::string> seriesFiles(const VolumeSource& source) {
  const auto* series = dynamic_cast<const SeriesSource*>(&source);
  return series ? series->files() : std::vector<std::string>{};
}

}  // namespace pvr::core
