// Small helpers shared by the pvr Tcl extension: errors with -errorcode,
// the exception type that carries one up to the Tcl boundary, parsers of
// option values, and JSON as Tcl values.
//
// Inside the extension a failure throws TclError; every Tcl_ObjCmdProc and
// every event-loop callback catches at its top, so no C++ exception unwinds
// through Tcl frames (docs/pvrsh.md lists the codes).
#pragma once

#include <tcl.h>

#include <initializer_list>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "tcl_error.h"

namespace pvr::tcl {

// Throws TclError{{"PVR", "ARGS", what}, message}.
[[noreturn]] void argsError(const std::string& what, const std::string& message);

// Sets the interpreter's result and -errorcode from `error`; returns TCL_ERROR.
int setError(Tcl_Interp* interp, const TclError& error);

// The same for a message and code list given apart.
int setError(Tcl_Interp* interp, std::initializer_list<std::string> code, const std::string& message);

// Makes a Tcl list object of strings.
Tcl_Obj* listOf(const std::vector<std::string>& items);

// Parses "X,Y,Z"-style number lists: separators are commas, spaces or an 'x'
// (for "512x512"). Throws argsError naming `option` when a piece is not a
// number or the count differs from `count` (any count when count < 0).
std::vector<double> parseNumbers(const std::string& option, const std::string& text, int count);

// The numbers of a Tcl list whose elements may be lists themselves:
// "{0 0 0 0 0} {1 1 1 1 1}" gives what "0 0 0 0 0 1 1 1 1 1" gives. An
// element that is no list splits as parseNumbers splits ("1,2,3").
std::vector<double> parseListNumbers(const std::string& option, const std::string& text);

// An integer in [lo, hi] or argsError naming `option`.
long parseInteger(const std::string& option, const std::string& text, long lo, long hi);

// A Tcl boolean (1, 0, on, off, yes, no, true, false) or argsError.
bool parseBoolean(const std::string& option, const std::string& text);

// A JSON value as Tcl: objects become dicts, arrays lists, null "".
Tcl_Obj* jsonToTcl(const nlohmann::json& value);

}  // namespace pvr::tcl
