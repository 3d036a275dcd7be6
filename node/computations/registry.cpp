// The computations the ranks know, one line each, and the rules for their
// parameters (computation.h).
#include <charconv>

#include "computation.h"
#include "error.h"

namespace pvr::node {

// Defined in their own files, one per computation.
ComputationEntry grayScott();  // gray_scott.cpp

const std::vector<ComputationEntry>& computations() {
  static const std::vector<ComputationEntry> list{
      grayScott(),
  };
  return list;
}

std::string parameterText(double v) {
  char text[32];
  return std::string(text, std::to_chars(text, text + sizeof text, v).ptr);
}

namespace {

std::string rangeOf(const ParameterSpec& p) { return "[" + parameterText(p.min) + ", " + parameterText(p.max) + "]"; }

}  // namespace

const ComputationEntry& computationNamed(std::string_view name) {
  std::string known;
  for (const ComputationEntry& c : computations()) {
    if (c.name == name) return c;
    known += (known.empty() ? "" : ", ") + std::string(c.name);
  }
  throw Error(ErrorCode::kInvalidArgument,
              "volume.computation: no computation '" + std::string(name) + "' (known: " + known + ")");
}

std::string parameterRanges(const ComputationEntry& entry) {
  std::string out;
  for (const ParameterSpec& p : entry.parameters)
    out += (out.empty() ? "" : ", ") + std::string(p.name) + " " + rangeOf(p);
  return out;
}

Parameters::Parameters(const ComputationEntry& entry, const std::map<std::string, double>& given)
    : entry_(&entry) {
  for (const ParameterSpec& p : entry.parameters) values_.push_back(p.initial);
  for (const auto& [name, value] : given) {
    std::size_t i = 0;
    while (i < entry.parameters.size() && entry.parameters[i].name != name) ++i;
    if (i == entry.parameters.size())
      throw Error(ErrorCode::kInvalidArgument, "parameters." + name + ": " + std::string(entry.name) +
                                                   " has no parameter '" + name + "' (its parameters: " +
                                                   parameterRanges(entry) + ")");
    const ParameterSpec& p = entry.parameters[i];
    if (!(value >= p.min && value <= p.max))
      throw Error(ErrorCode::kInvalidArgument, "parameters." + name + ": " + parameterText(value) +
                                                   " is outside the range " + rangeOf(p) + " of " +
                                                   std::string(entry.name) + "'s parameter '" + name + "'");
    values_[i] = value;
  }
}

double Parameters::operator[](std::string_view name) const {
  for (std::size_t i = 0; i < entry_->parameters.size(); ++i)
    if (entry_->parameters[i].name == name) return values_[i];
  throw Error(ErrorCode::kInternal,
              std::string(entry_->name) + " reads parameter '" + std::string(name) + "', which it does not declare");
}

}  // namespace pvr::node
