#include "tcl_util.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace pvr::tcl {

void argsError(const std::string& what, const std::string& message) { throw TclError({"PVR", "ARGS", what}, message); }

int setError(Tcl_Interp* interp, const TclError& error) {
  Tcl_SetObjResult(interp, Tcl_NewStringObj(error.what(), -1));
  Tcl_SetObjErrorCode(interp, listOf(error.code()));
  return TCL_ERROR;
}

int setError(Tcl_Interp* interp, std::initializer_list<std::string> code, const std::string& message) {
  return setError(interp, TclError(std::vector<std::string>(code), message));
}

Tcl_Obj* listOf(const std::vector<std::string>& items) {
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  for (const auto& s : items) Tcl_ListObjAppendElement(nullptr, list, Tcl_NewStringObj(s.data(), int(s.size())));
  return list;
}

std::vector<double> parseNumbers(const std::string& option, const std::string& text, int count) {
  std::vector<double> out;
  std::string piece;
  auto flush = [&] {
    if (piece.empty()) return;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(piece.c_str(), &end);
    if (end == piece.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
      argsError(option.substr(1), option + ": '" + piece + "' is not a number in '" + text + "'");
    out.push_back(v);
    piece.clear();
  };
  for (char c : text) {
    if (c == ',' || c == 'x' || c == 'X' || std::isspace(static_cast<unsigned char>(c)))
      flush();
    else
      piece += c;
  }
  flush();
  if (count >= 0 && int(out.size()) != count)
    argsError(option.substr(1), option + " needs " + std::to_string(count) + " numbers, got '" + text + "'");
  return out;
}

std::vector<double> parseListNumbers(const std::string& option, const std::string& text) {
  int count = 0;
  const char** items = nullptr;
  if (Tcl_SplitList(nullptr, text.c_str(), &count, &items) != TCL_OK)
    argsError(option.substr(1), option + ": not a Tcl list: '" + text + "'");
  const std::vector<std::string> elements(items, items + count);
  Tcl_Free(reinterpret_cast<char*>(items));
  std::vector<double> out;
  for (const std::string& element : elements) {
    // An element with white space is a list of its own (each level is
    // shorter than the last, so this ends); a single word is read as numbers.
    const auto inner = element.find_first_of(" \t\r\n") != std::string::npos ? parseListNumbers(option, element)
                                                                              : parseNumbers(option, element, -1);
    out.insert(out.end(), inner.begin(), inner.end());
  }
  return out;
}

long parseInteger(const std::string& option, const std::string& text, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
    argsError(option.substr(1), option + " needs an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                                    ", got '" + text + "'");
  return v;
}

bool parseBoolean(const std::string& option, const std::string& text) {
  int b = 0;
  if (Tcl_GetBoolean(nullptr, text.c_str(), &b) != TCL_OK)
    argsError(option.substr(1), option + " needs a boolean (on/off, 1/0), got '" + text + "'");
  return b != 0;
}

Tcl_Obj* jsonToTcl(const nlohmann::json& value) {
  if (value.is_object()) {
    Tcl_Obj* dict = Tcl_NewDictObj();
    for (const auto& [k, v] : value.items()) Tcl_DictObjPut(nullptr, dict, Tcl_NewStringObj(k.c_str(), -1), jsonToTcl(v));
    return dict;
  }
  if (value.is_array()) {
    Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
    for (const auto& v : value) Tcl_ListObjAppendElement(nullptr, list, jsonToTcl(v));
    return list;
  }
  if (value.is_null()) return Tcl_NewObj();
  if (value.is_boolean()) return Tcl_NewBooleanObj(value.get<bool>());
  if (value.is_number_integer()) return Tcl_NewWideIntObj(Tcl_WideInt(value.get<std::int64_t>()));
  if (value.is_number()) return Tcl_NewDoubleObj(value.get<double>());
  const std::string s = value.get<std::string>();
  return Tcl_NewStringObj(s.data(), int(s.size()));
}

}  // namespace pvr::tcl
