// Classified transfer functions: the tables the ray caster looks up.
//
// A TransferTable samples the piecewise-linear transfer function at kEntries
// scalars across its control points and stores, per entry, the premultiplied
// colour and the opacity of ONE ray step h: alpha = 1 - (1 - a)^(h / unit).
// Outside the control points the function is clamped, so the table domain is
// the control-point range and never depends on the data: every brick of a
// split classifies a scalar identically. Non-finite scalars never reach a
// table: the kernels classify them as empty before the look-up.
//
// A PreintegratedTable holds what pre-integration needs to integrate a
// ray segment whose scalar varies linearly between its ends exactly, for
// any step: the cumulative integrals of the extinction and of the
// extinction-weighted colour over the scalar (preintegration.h). It does
// not depend on the step, and building it costs what the plain table does.
#pragma once

#include <cstdint>
#include <vector>

#include "image.h"
#include "preintegration.h"
#include "scene.h"

namespace pvr::core {

// Extinction and colour of a transfer function at one scalar, in double:
// the continuous model that references integrate and tables sample.
struct Medium {
  double r = 0, g = 0, b = 0;  // linear colour (the transfer function's sRGB decoded), not premultiplied
  double tau = 0;              // extinction per world unit: -ln(1 - a) / unit_distance
};
Medium evaluateMedium(const TransferFunctionSpec& tf, double scalar);

class TransferTable {
 public:
  static constexpr int kEntries = 4096;

  TransferTable() = default;
  TransferTable(const TransferFunctionSpec& tf, double step);

  // Table coordinate of a scalar: scalar * scale + offset, in [0, kEntries-1].
  float scale() const { return scale_; }
  float offset() const { return offset_; }
  const Rgba* entries() const { return entries_.data(); }  // kEntries entries

  // True if some scalar in [lo, hi] has non-zero opacity. O(1) (prefix sums).
  bool anyVisible(double lo, double hi) const;

 private:
  float scale_ = 0, offset_ = 0;
  std::vector<Rgba> entries_;
  std::vector<std::uint32_t> visiblePrefix_;  // visiblePrefix_[i] = visible entries below i
};

// The transfer function as an extinction medium, for mixing several
// volumes (docs/scene.md, "Several volumes"): per entry the optical depth
// of ONE ray step, d = tau h, and the linear colour weighted by it,
// (c d, d) stored as (r, g, b, a). Depths of overlapping volumes add, and
// so do their weighted colours; a sample of w steps then has opacity
// 1 - exp(-w D) and premultiplied colour (sum c d) / D times that opacity.
// Opacity 1 is evaluateMedium's saturating extinction: its depth
// 1e30 h stays finite in float. Same table domain as TransferTable.
class ExtinctionTable {
 public:
  static constexpr int kEntries = TransferTable::kEntries;

  ExtinctionTable() = default;
  ExtinctionTable(const TransferFunctionSpec& tf, double step);

  float scale() const { return scale_; }
  float offset() const { return offset_; }
  const Rgba* entries() const { return entries_.data(); }  // kEntries entries

 private:
  float scale_ = 0, offset_ = 0;
  std::vector<Rgba> entries_;
};

class PreintegratedTable {
 public:
  static constexpr int kEntries = TransferTable::kEntries;

  PreintegratedTable() = default;
  explicit PreintegratedTable(const TransferFunctionSpec& tf);

  // Valid while this table lives and is not moved from.
  PreintegralTables tables() const;

 private:
  float scale_ = 0, offset_ = 0;
  std::vector<PreintegralCell> cells_;
  std::vector<PreintegralRows> rows_;  // cells_ as rows
  bool opaqueNodes_ = false;
  std::vector<std::uint32_t> visibleBelow_;
  std::vector<Rgba> opaqueColour_;
  float clearBelow_ = -INFINITY, clearAbove_ = INFINITY;  // PreintegralTables
  bool gaps_ = true;
};

}  // namespace pvr::core
