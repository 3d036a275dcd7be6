// Package pvr: Pvr_Init registers `pvr_session`, which makes session
// objects (paper 003, Table 1). Loaded by `package require pvr`.
#include <tcl.h>

#include <string>

#include "session.h"
#include "session_help.h"

namespace pvr::tcl {
namespace {

// pvr_session NAME: creates the object command NAME (":brain") for a new,
// closed session. Results: NAME. Side effects: a new command; an existing
// command of that name is an error, not replaced.
// pvr_session help ?SUBCOMMAND?: the session objects' help (session_help.h)
// as the result; "help" is therefore not a session name.
int sessionCreateCmd(ClientData, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if ((objc == 2 || objc == 3) && std::string(Tcl_GetString(objv[1])) == "help") {
    try {
      const std::string text =
          (objc == 2 ? "pvr_session NAME\n    make the session object NAME (e.g. :s), closed\n" : "") +
          subcommandHelp("NAME", objc == 3 ? Tcl_GetString(objv[2]) : "");
      Tcl_SetObjResult(interp, Tcl_NewStringObj(text.c_str(), int(text.size()) - 1));
      return TCL_OK;
    } catch (const TclError& e) {
      return setError(interp, e);
    }
  }
  if (objc != 2) {
    Tcl_WrongNumArgs(interp, 1, objv, "name");
    Tcl_SetErrorCode(interp, "PVR", "ARGS", "WRONGNUM", nullptr);
    return TCL_ERROR;
  }
  const std::string name = Tcl_GetString(objv[1]);
  if (name.empty()) return setError(interp, {"PVR", "ARGS", "NAME"}, "pvr_session: the name must not be empty");
  Tcl_CmdInfo info;
  if (Tcl_GetCommandInfo(interp, name.c_str(), &info))
    return setError(interp, {"PVR", "ARGS", "EXISTS"}, "pvr_session: command \"" + name + "\" already exists");
  auto* session = new Session(interp, name);
  session->token_ = Tcl_CreateObjCommand(interp, name.c_str(), Session::objCmd, session, Session::deleteCmd);
  Tcl_SetObjResult(interp, objv[1]);
  return TCL_OK;
}

}  // namespace
}  // namespace pvr::tcl

extern "C" __attribute__((visibility("default"))) int Pvr_Init(Tcl_Interp* interp) {
  if (!Tcl_InitStubs(interp, "8.6", 0)) return TCL_ERROR;
  // ::pvr::progress: when true (pvrsh running a script sets it), sequences
  // print progress and a timing table on stderr.
  if (Tcl_Eval(interp, "namespace eval ::pvr { if {![info exists progress]} { variable progress 0 } }") != TCL_OK)
    return TCL_ERROR;
  // ::pvr::phases: the phases of every timing dict, in order, for graphs
  // and tables written in Tcl.
  if (!Tcl_SetVar2Ex(interp, "::pvr::phases", nullptr, pvr::tcl::phaseNames(), TCL_GLOBAL_ONLY | TCL_LEAVE_ERR_MSG))
    return TCL_ERROR;
  Tcl_CreateObjCommand(interp, "pvr_session", pvr::tcl::sessionCreateCmd, nullptr, nullptr);
  return Tcl_PkgProvide(interp, "pvr", PVR_PACKAGE_VERSION);
}
