// Timings of render sequences for people and scripts: the progress line and
// the table pvrsh prints on stderr, and the Tcl dicts of the image callback
// and `timing`.
#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "session.h"

namespace pvr::tcl {

bool progressOn(Tcl_Interp* interp) {
  const char* v = Tcl_GetVar2(interp, "::pvr::progress", nullptr, TCL_GLOBAL_ONLY);
  int on = 0;
  return v && Tcl_GetBoolean(nullptr, v, &on) == TCL_OK && on;
}

Tcl_Obj* timingDict(const FrameRecord& r) {
  Tcl_Obj* d = Tcl_NewDictObj();
  const auto put = [&](const char* k, double v) { Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(k, -1), Tcl_NewDoubleObj(v)); };
  put("dist", r.timing.distribute);
  put("rend", r.timing.render);
  put("comp", r.timing.composite);
  put("comm", r.timing.communicate);
  put("send", r.timing.send);
  put("arrival", r.arrival);
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("width", -1), Tcl_NewIntObj(r.width));
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("height", -1), Tcl_NewIntObj(r.height));
  return d;
}

Tcl_Obj* Session::timingObj() const {
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  for (const auto& r : last_.frames) {
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

void Session::printTable(const Sequence& seq) const {
  const double total = seq.frames.back().arrival;
  std::fprintf(stderr, "%s %s: %zu frames in %.3f s (%.2f fps)%s\n", name_.c_str(), seq.label.c_str(),
               seq.frames.size(), total, total > 0 ? double(seq.frames.size()) / total : 0.0,
               seq.cancelled ? ", cancelled" : "");
  std::fprintf(stderr, "%6s %9s %9s %9s %9s %9s %9s\n", "frame", "dist", "rend", "comp", "comm", "send", "arrival");
  proto::FrameTiming sum;
  for (const auto& r : seq.frames) {
    std::fprintf(stderr, "%6u %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f\n", r.frame, r.timing.distribute, r.timing.render,
                 r.timing.composite, r.timing.communicate, r.timing.send, r.arrival);
    sum.distribute += r.timing.distribute;
    sum.render += r.timing.render;
    sum.composite += r.timing.composite;
    sum.communicate += r.timing.communicate;
    sum.send += r.timing.send;
  }
  const double all = sum.distribute + sum.render + sum.composite + sum.communicate + sum.send;
  const auto share = [&](double v) { return all > 0 ? 100.0 * v / all : 0.0; };
  std::fprintf(stderr, "breakdown (s, share): dist %.3f (%.0f%%)  rend %.3f (%.0f%%)  comp %.3f (%.0f%%)  "
                       "comm %.3f (%.0f%%)  send %.3f (%.0f%%)\n",
               sum.distribute, share(sum.distribute), sum.render, share(sum.render), sum.composite,
               share(sum.composite), sum.communicate, share(sum.communicate), sum.send, share(sum.send));
}

}  // namespace pvr::tcl
