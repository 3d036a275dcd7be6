// pvrsh: a Tk shell with package pvr loaded. With no DISPLAY, or with
// -nogui, it is a Tcl shell. It runs a script file (pvrsh ?-nogui? FILE
// ?ARG ...?) or reads commands interactively.
//
// A script run this way sets ::pvr::progress, so render sequences print
// progress and a timing table on stderr; an error in the script exits 1.
#include <tcl.h>
#include <tk.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

bool gRunsScript = false;

// `pvrsh --help`; the session commands' own help is `pvr_session help`.
constexpr const char* kUsage =
    "usage: pvrsh ?-nogui? ?script.tcl ?arg ...??\n"
    "\n"
    "A Tcl/Tk shell with package pvr loaded: pvr_session makes session objects that drive a pvrd\n"
    "server. With a display it is a Tk shell, otherwise a Tcl shell. With a script it runs the\n"
    "script (argv holds the args) with progress lines and timing tables on stderr, and exits 1\n"
    "on an error; without one it reads commands.\n"
    "\n"
    "options:\n"
    "  -nogui       a Tcl shell even with a display\n"
    "  -h, --help   print this help and exit\n"
    "\n"
    "in the shell:\n"
    "  pvr_session help ?subcommand?   every session subcommand, or one (set: every option)\n"
    "\n"
    "example:\n"
    "  pvrsh -nogui\n"
    "  % pvr_session :s\n"
    "  % :s open 127.0.0.1:7350 -ranks 2\n"
    "  % :s set -dataset ct_head_cranium/ct_head_cranium.json -imagesz 512,512\n"
    "  % :s image file head.png; :s render frame; :s wait\n";

// Finds package pvr next to the executable (installed: PREFIX/bin/../lib),
// in the build tree, or on the usual auto_path, then loads it. Each
// directory goes to the front, the one next to the executable last, so an
// installed pvrsh loads its own package even while the build tree exists.
int loadPvr(Tcl_Interp* interp) {
  const std::string script = std::string(R"TCL(
    set exe [file dirname [file normalize [info nameofexecutable]]]
    foreach dir [list )TCL") + "{" PVR_BUILD_PACKAGE_DIR "}" + R"TCL( [file join [file dirname $exe] lib]] {
      # To the front even when Tcl put it further back (it adds PREFIX/lib).
      if {[file exists [file join $dir pvr pkgIndex.tcl]]} {
        set ::auto_path [linsert [lsearch -all -inline -not -exact $::auto_path $dir] 0 $dir]
      }
    }
    unset exe dir
    package require pvr
  )TCL";
  if (Tcl_Eval(interp, script.c_str()) != TCL_OK) return TCL_ERROR;
  if (gRunsScript) Tcl_SetVar2(interp, "::pvr::progress", nullptr, "1", TCL_GLOBAL_ONLY);
  if (!gRunsScript) {
    // Interactive: an asynchronous error (a refused set, a failed render)
    // is one line on stderr as soon as it arrives, not a Tk dialog nor
    // silence until the next command (issue 14, point 6). ~/.pvrshrc,
    // read after this, may install another handler.
    constexpr const char* kReport = R"TCL(
      proc ::pvr::reportBackgroundError {message options} {
          puts stderr "pvrsh: $message"
          flush stderr
      }
      interp bgerror {} ::pvr::reportBackgroundError
    )TCL";
    if (Tcl_Eval(interp, kReport) != TCL_OK) return TCL_ERROR;
  }
  Tcl_SetVar(interp, "tcl_rcFileName", "~/.pvrshrc", TCL_GLOBAL_ONLY);
  return TCL_OK;
}

// The Tcl shell's loop while it reads commands: Tcl_Main reads standard
// input through a channel handler while this runs the event loop, so the
// sessions' replies and errors are handled between commands too (a plain
// Tcl_Main blocks in gets and handles them only at the next command). It
// ends when standard input is at its end, as Tcl_Main's own reading does.
void interactiveLoop() {
  while (Tcl_Channel in = Tcl_GetStdChannel(TCL_STDIN)) {
    if (Tcl_Eof(in)) break;
    Tcl_DoOneEvent(TCL_ALL_EVENTS);
  }
}

int tclAppInit(Tcl_Interp* interp) {
  if (Tcl_Init(interp) != TCL_OK) return TCL_ERROR;
  // Tk has its own loop; with a script Tcl_Main would enter this one after
  // it instead of exiting.
  if (!gRunsScript) Tcl_SetMainLoop(interactiveLoop);
  return loadPvr(interp);
}

int tkAppInit(Tcl_Interp* interp) {
  if (Tcl_Init(interp) != TCL_OK || Tk_Init(interp) != TCL_OK) return TCL_ERROR;
  Tcl_StaticPackage(interp, "Tk", Tk_Init, Tk_SafeInit);
  return loadPvr(interp);
}

}  // namespace

int main(int argc, char** argv) {
  // -nogui (anywhere before the script name) chooses the Tcl shell.
  bool gui = std::getenv("DISPLAY") && *std::getenv("DISPLAY");
  std::vector<char*> args{argv[0]};
  int i = 1;
  for (; i < argc && argv[i][0] == '-'; ++i) {
    if (std::strcmp(argv[i], "-nogui") == 0) {
      gui = false;
    } else if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) {
      std::fputs(kUsage, stdout);
      return 0;
    } else {
      break;
    }
  }
  for (; i < argc; ++i) args.push_back(argv[i]);
  gRunsScript = args.size() > 1;
  args.push_back(nullptr);
  if (gui)
    Tk_Main(int(args.size() - 1), args.data(), tkAppInit);
  else
    Tcl_Main(int(args.size() - 1), args.data(), tclAppInit);
  return 0;
}
