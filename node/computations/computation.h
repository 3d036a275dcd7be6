// User computations on the render ranks (docs/steering.md): the extension
// point of computational steering.
//
// A computation is a set of scalar fields on the scene's grid that a step
// function advances in time. Each render cluster runs it over the k-d
// decomposition it renders: every rank steps the nodes of its own brick and
// gets the nodes around it (ghost layers) from the ranks that own them
// through the cluster's communicator (computation_run.h does that for every
// computation). The field the renderer draws is one of them, rebuilt into a
// brick after each step.
//
// Adding one: a file NAME.cpp in this folder that defines a function
// returning its ComputationEntry, plus one line in registry.cpp. The
// parameters it declares are what `:s set -param NAME VALUE` sets and
// `:s list status` shows; nothing else lists them.
#pragma once

#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "grid.h"

namespace pvr::node {

// One steering parameter: its name, value before anyone sets it, the
// closed range a value must lie in, and a line of help.
struct ParameterSpec {
  std::string_view name;
  double initial = 0;
  double min = 0, max = 0;
  std::string_view help;
};

struct ComputationEntry;

// The values of a computation's parameters: the scene's "parameters" over
// the declared defaults, each checked against its range.
class Parameters {
 public:
  // Throws pvr::Error (kInvalidArgument) for a name the computation does not
  // declare or a value outside its range, naming the parameter and the range.
  Parameters(const ComputationEntry& entry, const std::map<std::string, double>& given);
  // The value of a declared parameter (a name not declared is a bug in the
  // computation: pvr::Error kInternal).
  double operator[](std::string_view name) const;

 private:
  const ComputationEntry* entry_;
  std::vector<double> values_;  // in the entry's declaration order
};

// Several scalar fields (doubles) over one box of grid nodes: a rank's owned
// nodes plus the ghost layers around them. Storage is x fastest, then y, z.
class FieldBlock {
 public:
  FieldBlock() = default;
  FieldBlock(int fields, const core::NodeBox& box);

  const core::NodeBox& box() const { return box_; }
  int fields() const { return fields_; }
  // Index of global node `n` (inside box()) in a field's storage; the
  // neighbours of index i are i -+ 1 (x), i -+ strideY(), i -+ strideZ().
  std::size_t index(core::IVec3 n) const {
    return std::size_t(((n.z - box_.lo.z) * extents_.y + (n.y - box_.lo.y)) * extents_.x + (n.x - box_.lo.x));
  }
  std::int64_t strideY() const { return extents_.x; }
  std::int64_t strideZ() const { return extents_.x * extents_.y; }
  double* field(int f) { return values_.data() + std::size_t(f) * nodes_; }
  const double* field(int f) const { return values_.data() + std::size_t(f) * nodes_; }

 private:
  int fields_ = 0;
  core::NodeBox box_{{0, 0, 0}, {-1, -1, -1}};
  core::IVec3 extents_{0, 0, 0};
  std::size_t nodes_ = 0;
  std::vector<double> values_;
};

// What a step function is given.
struct StepArgs {
  const FieldBlock& now;   // every field at the current step, on the owned nodes and `halo` layers around them
  FieldBlock& next;        // to write: every field at the next step, on the owned nodes
  const core::NodeBox& owned;
  const core::GridGeometry& grid;  // the whole grid (its edges are the boundary)
  const Parameters& parameters;
};

// A computation, as registry.cpp lists it.
struct ComputationEntry {
  std::string_view name;     // what a scene's volume.computation names
  std::string_view summary;  // one line for status and docs
  std::vector<ParameterSpec> parameters;
  std::vector<std::string_view> fields;  // the fields' names, in storage order
  int halo = 1;  // ghost layers one step reads around the owned nodes
  // Every field's value at `node` at step 0. Deterministic and a function of
  // the global node alone, so any decomposition starts from the same state.
  void (*initial)(const core::GridGeometry& grid, core::IVec3 node, std::span<double> values) = nullptr;
  // Writes the next step at every owned node from `now` (the same rule on
  // every rank, so shared node planes agree bit for bit).
  void (*step)(const StepArgs& args) = nullptr;
  // The field the renderer draws, given the parameters.
  int (*shown)(const Parameters& parameters) = nullptr;
};

// Every registered computation, in the order to list them (registry.cpp).
const std::vector<ComputationEntry>& computations();
// The one named `name`; throws pvr::Error (kInvalidArgument) naming it and
// the known ones.
const ComputationEntry& computationNamed(std::string_view name);
// "feed [0, 0.1], kill [0, 0.1]": the parameters with their ranges, for messages.
std::string parameterRanges(const ComputationEntry& entry);
// A parameter's value as messages and status write it: the shortest text
// that reads back as the same double.
std::string parameterText(double value);

}  // namespace pvr::node
