#include "commonroad/xml_source.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace frenetic::commonroad {

namespace {

std::string_view Trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

// Element text shortened for a message (a mangled file may hold anything there: Error makes the
// whole message Printable).
std::string Quote(std::string_view text) {
  std::string out(1, '\'');
  out.append(text.substr(0, 40));
  out += text.size() > 40 ? "...'" : "'";
  return out;
}

}  // namespace

std::string Printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const unsigned c = static_cast<unsigned char>(text[i]);
    // A well-formed UTF-8 sequence (RFC 3629: no overlong forms, no surrogates, nothing above
    // U+10FFFF): its length n by the lead byte, the second byte within [lo, hi], the others
    // continuation bytes.
    std::size_t n = 0;
    unsigned lo = 0x80, hi = 0xBF;
    if (c >= 0x20 && c < 0x7F) {
      n = 1;
    } else if (c >= 0xC2 && c <= 0xDF) {
      n = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
      n = 3;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      n = 4;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    }
    bool whole = n > 0 && i + n <= text.size();
    for (std::size_t k = 1; whole && k < n; ++k) {
      const unsigned b = static_cast<unsigned char>(text[i + k]);
      whole = k == 1 ? b >= lo && b <= hi : b >= 0x80 && b <= 0xBF;
    }
    if (whole) {
      out.append(text.substr(i, n));
      i += n;
      continue;
    }
    if (c == '\n' || c == '\r' || c == '\t') {
      out += ' ';
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xF];
    }
    ++i;
  }
  return out;
}

StatusOr<std::string> ReadXmlFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return Status::Error(path + ": not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read error");
  return text.str();
}

std::optional<double> ParseFiniteDouble(std::string_view text) {
  text = Trim(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  double v = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(v)) {
    return std::nullopt;
  }
  return v;
}

std::optional<int> ParseInt(std::string_view text) {
  text = Trim(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  int v = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size()) return std::nullopt;
  return v;
}

XmlSource::XmlSource(std::string_view text, std::string_view source)
    : text_(text), source_(source) {
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') line_starts_.push_back(i + 1);
  }
}

Status XmlSource::Parse(pugi::xml_document* doc) const {
  const pugi::xml_parse_result result =
      doc->load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
  if (result) return Status::Ok();
  const size_t offset = result.offset < 0 ? 0 : static_cast<size_t>(result.offset);
  const int line =
      1 + static_cast<int>(std::upper_bound(line_starts_.begin(), line_starts_.end(), offset) -
                           line_starts_.begin());
  return Status::Error(source_ + ":" + std::to_string(line) + ": XML syntax error: " +
                       result.description());
}

int XmlSource::Line(const pugi::xml_node& node) const {
  const ptrdiff_t offset = node.offset_debug();
  if (offset < 0) return 0;
  return 1 + static_cast<int>(std::upper_bound(line_starts_.begin(), line_starts_.end(),
                                               static_cast<size_t>(offset)) -
                              line_starts_.begin());
}

std::string XmlSource::Path(const pugi::xml_node& node) const {
  std::vector<std::string> parts;
  for (pugi::xml_node n = node; n && n.type() == pugi::node_element && n.parent() &&
                                n.parent().type() == pugi::node_element;
       n = n.parent()) {
    std::string part = n.name();
    if (const pugi::xml_attribute id = n.attribute("id")) part += std::string(" ") + id.value();
    parts.push_back(std::move(part));
  }
  if (parts.empty()) return node.type() == pugi::node_element ? node.name() : "document";
  std::string path;
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
    if (!path.empty()) path += "/";
    path += *it;
  }
  return path;
}

Status XmlSource::Error(const pugi::xml_node& node, std::string_view message) const {
  std::string text = source_ + ":" + std::to_string(Line(node)) + ": " + Path(node) + ": ";
  text += message;
  return Status::Error(Printable(text));
}

Status XmlSource::Child(const pugi::xml_node& node, const char* name, pugi::xml_node* out) const {
  *out = node.child(name);
  if (!*out) return Error(node, std::string("missing <") + name + ">");
  return Status::Ok();
}

Status XmlSource::Number(const pugi::xml_node& node, double* out) const {
  const char* text = node.child_value();
  const std::optional<double> v = ParseFiniteDouble(text);
  if (!v) return Error(node, Quote(text) + " is not a finite number");
  *out = *v;
  return Status::Ok();
}

Status XmlSource::Integer(const pugi::xml_node& node, int* out) const {
  const char* text = node.child_value();
  const std::optional<int> v = ParseInt(text);
  if (!v) return Error(node, Quote(text) + " is not an integer");
  *out = *v;
  return Status::Ok();
}

Status XmlSource::ChildNumber(const pugi::xml_node& node, const char* name, double* out) const {
  pugi::xml_node child;
  FRENETIC_CR_TRY(Child(node, name, &child));
  return Number(child, out);
}

Status XmlSource::AttrInt(const pugi::xml_node& node, const char* name, int* out) const {
  const pugi::xml_attribute a = node.attribute(name);
  if (!a) return Error(node, std::string("missing attribute ") + name);
  const std::optional<int> v = ParseInt(a.value());
  if (!v) return Error(node, std::string("attribute ") + name + " " + Quote(a.value()) +
                                 " is not an integer");
  *out = *v;
  return Status::Ok();
}

Status XmlSource::AttrNumber(const pugi::xml_node& node, const char* name, double* out) const {
  const pugi::xml_attribute a = node.attribute(name);
  if (!a) return Error(node, std::string("missing attribute ") + name);
  const std::optional<double> v = ParseFiniteDouble(a.value());
  if (!v) return Error(node, std::string("attribute ") + name + " " + Quote(a.value()) +
                                 " is not a finite number");
  *out = *v;
  return Status::Ok();
}

Status XmlSource::AttrString(const pugi::xml_node& node, const char* name,
                             std::string* out) const {
  const pugi::xml_attribute a = node.attribute(name);
  if (!a) return Error(node, std::string("missing attribute ") + name);
  *out = a.value();
  return Status::Ok();
}

}  // namespace frenetic::commonroad
