// `:s volume add|remove|configure|list` (issue 12): the session's volumes,
// one row of session_commands.cpp's subcommand table. The list itself and
// the changes it makes are volume_list.h's.
#pragma once

#include <tcl.h>

#include <string>

namespace pvr::tcl {

class Session;

// The `volume` subcommand: objv[0] is the session, objv[1] "volume".
int volumeCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]);

// `:s help volume`'s part after the usage line: each action with its
// usage and summary, then the options of add and configure.
std::string volumeHelp(const std::string& object);

}  // namespace pvr::tcl
