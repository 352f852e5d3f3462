// Reading values out of a pugixml document with errors that name the source, the line and the
// element (private to the commonroad module: the scenario and the solution readers share it).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <pugixml.hpp>

#include "frenetic/status.h"

namespace frenetic::commonroad {

// The whole text of the file at `path`, or an error naming it: not a file, cannot open, read
// error (the scenario and the solution loaders).
StatusOr<std::string> ReadXmlFile(const std::string& path);

// `text` fit for a one-line message in a terminal, a log or JSON: its well-formed UTF-8 as it
// is, a newline, carriage return or tab as a space, and every other control character or byte
// that is not well-formed UTF-8 as \xNN (a mangled file may hold any bytes).
std::string Printable(std::string_view text);

// The XML text and its name. Every Status it returns is one line:
//   "<source>:<line>: <path>: <message>"
// where <path> names the element and its ancestors below the root, with their ids, e.g.
// "lanelet 30622/leftBound/point".
class XmlSource {
 public:
  XmlSource(std::string_view text, std::string_view source);

  // Parses the text into `doc`; a syntax error names its line.
  Status Parse(pugi::xml_document* doc) const;

  const std::string& source() const { return source_; }
  int Line(const pugi::xml_node& node) const;
  std::string Path(const pugi::xml_node& node) const;
  Status Error(const pugi::xml_node& node, std::string_view message) const;

  // The element's child `name`, or an error naming what is missing.
  Status Child(const pugi::xml_node& node, const char* name, pugi::xml_node* out) const;
  // The element's text as a number: finite, else an error. A leading '+' and surrounding white
  // space are accepted.
  Status Number(const pugi::xml_node& node, double* out) const;
  Status Integer(const pugi::xml_node& node, int* out) const;
  // The child element's text as a number (required).
  Status ChildNumber(const pugi::xml_node& node, const char* name, double* out) const;
  // Attribute values (required).
  Status AttrInt(const pugi::xml_node& node, const char* name, int* out) const;
  Status AttrNumber(const pugi::xml_node& node, const char* name, double* out) const;
  Status AttrString(const pugi::xml_node& node, const char* name, std::string* out) const;

 private:
  std::string_view text_;
  std::string source_;
  std::vector<size_t> line_starts_;  // offsets where lines 2, 3, ... begin
};

// Parses `text` as a finite double / an int (whole text, white space trimmed, '+' allowed).
std::optional<double> ParseFiniteDouble(std::string_view text);
std::optional<int> ParseInt(std::string_view text);

}  // namespace frenetic::commonroad

// Returns the Status of `expr` from the enclosing function when it is an error.
#define FRENETIC_CR_TRY(expr)                     \
  do {                                            \
    ::frenetic::Status frenetic_cr_s_ = (expr);   \
    if (!frenetic_cr_s_.ok()) return frenetic_cr_s_; \
  } while (0)
