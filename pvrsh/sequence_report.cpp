// Timings of render sequences for people and scripts: the progress line and
// the table pvrsh prints on stderr, and the Tcl dicts of the image callback
// and `timing`.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <vector>

#include "session.h"

namespace pvr::tcl {

namespace {

// A frame's phases in FrameTiming's order, named as the timing dicts and
// the table name them (read, prep and dist are charged to the first frame
// after a dataset load or redistribution).
struct Phase {
  const char* name;
  double proto::FrameTiming::*value;
};
constexpr Phase kPhases[] = {{"read", &proto::FrameTiming::read},       {"prep", &proto::FrameTiming::preprocess},
                             {"dist", &proto::FrameTiming::distribute}, {"rend", &proto::FrameTiming::render},
                             {"comp", &proto::FrameTiming::composite},  {"comm", &proto::FrameTiming::communicate},
                             {"send", &proto::FrameTiming::send}};

}  // namespace

Tcl_Obj* phaseNames() {
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  for (const Phase& p : kPhases) Tcl_ListObjAppendElement(nullptr, list, Tcl_NewStringObj(p.name, -1));
  return list;
}

bool progressOn(Tcl_Interp* interp) {
  const char* v = Tcl_GetVar2(interp, "::pvr::progress", nullptr, TCL_GLOBAL_ONLY);
  int on = 0;
  return v && Tcl_GetBoolean(nullptr, v, &on) == TCL_OK && on;
}

Tcl_Obj* timingDict(const FrameRecord& r) {
  Tcl_Obj* d = Tcl_NewDictObj();
  const auto put = [&](const char* k, double v) { Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(k, -1), Tcl_NewDoubleObj(v)); };
  for (const Phase& p : kPhases) put(p.name, r.timing.*p.value);
  put("arrival", r.arrival);
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("width", -1), Tcl_NewIntObj(r.width));
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("height", -1), Tcl_NewIntObj(r.height));
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("quality", -1), Tcl_NewStringObj(r.coarse ? "coarse" : "full", -1));
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("reduction", -1), Tcl_NewIntObj(r.reduction));
  return d;
}

Tcl_Obj* Session::timingObj() const {
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  for (const auto& r : book_.latest().frames) {
    Tcl_Obj* d = timingDict(r);
    Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("frame", -1), Tcl_NewWideIntObj(r.frame));
    Tcl_ListObjAppendElement(nullptr, list, d);
  }
  return list;
}

void Session::printProgress(const Sequence& seq) const {
  const double elapsed = seconds(Clock::now() - seq.sent);
  const std::size_t done = seq.frames.size();
  const double fps = elapsed > 0 ? double(done) / elapsed : 0;
  const double left = fps > 0 ? double(seq.total - std::min<std::size_t>(done, seq.total)) / fps : 0;
  // On a terminal the line rewrites itself until the sequence ends.
  const bool tty = ::isatty(2);
  std::fprintf(stderr, "%s%s %s: %zu/%u frames, %.2f fps, %.1f s left%s", tty ? "\r" : "", name_.c_str(),
               seq.label.c_str(), done, seq.total, fps, left, tty && done < seq.total ? "" : "\n");
  std::fflush(stderr);
}

// The table of a finished sequence: one row per frame with each phase in
// milliseconds and the frame's arrival (seconds since the request went
// out), then mean, median and max rows over the frames, then each phase's
// total and share.
void Session::printTable(const Sequence& seq) const {
  const double total = seq.frames.back().arrival;
  std::fprintf(stderr, "%s %s: %zu frames in %.3f s (%.2f fps)%s\n", name_.c_str(), seq.label.c_str(),
               seq.frames.size(), total, total > 0 ? double(seq.frames.size()) / total : 0.0,
               seq.cancelled ? ", cancelled" : "");
  std::fprintf(stderr, "%6s", "frame");
  for (const Phase& p : kPhases) std::fprintf(stderr, " %6s ms", p.name);
  std::fprintf(stderr, " %9s s\n", "arrival");
  // Column k: phase k in seconds, the last one the arrival.
  constexpr std::size_t kColumns = std::size(kPhases) + 1;
  std::vector<std::vector<double>> columns(kColumns);
  for (const auto& r : seq.frames) {
    std::fprintf(stderr, "%6u", r.frame);
    for (std::size_t k = 0; k < std::size(kPhases); ++k) {
      const double v = r.timing.*kPhases[k].value;
      std::fprintf(stderr, " %9.2f", v * 1e3);
      columns[k].push_back(v);
    }
    std::fprintf(stderr, " %11.4f\n", r.arrival);
    columns.back().push_back(r.arrival);
  }
  // Summary rows; the arrival column's are of the gaps between arrivals
  // (the first frame's from the request), the time each frame added.
  std::vector<double>& gaps = columns.back();
  for (std::size_t i = gaps.size(); i-- > 1;) gaps[i] -= gaps[i - 1];
  const char* const kRows[] = {"mean", "median", "max"};
  for (int row = 0; row < 3; ++row) {
    std::fprintf(stderr, "%6s", kRows[row]);
    for (std::size_t k = 0; k < kColumns; ++k) {
      std::vector<double> v = columns[k];
      std::sort(v.begin(), v.end());
      double x = v.back();
      if (row == 0) {
        x = 0;
        for (double d : v) x += d;
        x /= double(v.size());
      } else if (row == 1) {
        x = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
      }
      if (k + 1 < kColumns)
        std::fprintf(stderr, " %9.2f", x * 1e3);
      else
        std::fprintf(stderr, " %11.4f", x);
    }
    std::fprintf(stderr, "%s\n", row == 0 ? "  (arrival: gap between frames)" : "");
  }
  double all = 0;
  for (const Phase& p : kPhases) {
    double sum = 0;
    for (const auto& r : seq.frames) sum += r.timing.*p.value;
    all += sum;
  }
  std::fprintf(stderr, "breakdown (s, share):");
  for (const Phase& p : kPhases) {
    double sum = 0;
    for (const auto& r : seq.frames) sum += r.timing.*p.value;
    std::fprintf(stderr, " %s %.3f (%.0f%%)", p.name, sum, all > 0 ? 100.0 * sum / all : 0.0);
  }
  std::fputc('\n', stderr);
}

}  // namespace pvr::tcl
