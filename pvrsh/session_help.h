// Help for people at the Tcl prompt: `:s help ?SUBCOMMAND?` and
// `pvr_session help ?SUBCOMMAND?` print the same text, made from the
// subcommand table of session_commands.cpp (and, for set, the option table
// of scene_options.cpp), so help and the commands cannot disagree.
#pragma once

#include <string>

namespace pvr::tcl {

// Every subcommand of the session object `object` (":s") with its usage and
// a one-line summary, or only `subcommand`'s when it is not empty (for
// "set", followed by every option with its value form and default; for
// "volume", by its actions and their options).
// Throws TclError {PVR ARGS SUBCOMMAND} naming the subcommands for an
// unknown one.
std::string subcommandHelp(const std::string& object, const std::string& subcommand);

}  // namespace pvr::tcl
