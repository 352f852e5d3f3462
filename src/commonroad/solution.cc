#include "frenetic/commonroad/solution.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <pugixml.hpp>

#include "commonroad/xml_source.h"

namespace frenetic::commonroad {

namespace {

// CommonRoad's cost function ids (commonroad-io common/solution.py, CostFunction), and TR2, the
// traffic-rule cost function of the drivability checker's traffic-rule evaluation set (its highD
// solution files are "KS1:TR2:<scenario id>:2020a").
constexpr const char* kCostIds[] = {"JB1", "SA1", "WX1", "SM1", "SM2", "SM3", "MW1", "TR1", "TR2"};

bool KnownCost(std::string_view id) {
  return std::find(std::begin(kCostIds), std::end(kCostIds), id) != std::end(kCostIds);
}

std::string Number(double v) {
  char buffer[64];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return ec == std::errc() ? std::string(buffer, ptr) : std::string("nan");
}

std::string JoinIds(const std::vector<std::string>& ids) {
  if (ids.size() == 1) return ids.front();
  std::string out = "[";
  for (size_t i = 0; i < ids.size(); ++i) out += (i ? "," : "") + ids[i];
  return out + "]";
}

std::vector<std::string> SplitIds(std::string_view text) {
  if (!text.empty() && text.front() == '[' && text.back() == ']') {
    text = text.substr(1, text.size() - 2);
  }
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    out.emplace_back(text.substr(start, comma == std::string_view::npos ? comma : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

// The four colon-separated fields; a bracketed list may hold no colon of its own.
std::vector<std::string> SplitBenchmarkId(std::string_view id) {
  std::vector<std::string> parts;
  size_t start = 0;
  int depth = 0;
  for (size_t i = 0; i <= id.size(); ++i) {
    const char c = i < id.size() ? id[i] : ':';
    if (c == '[') ++depth;
    if (c == ']') --depth;
    if (c == ':' && depth == 0) {
      parts.emplace_back(id.substr(start, i - start));
      start = i + 1;
    }
  }
  return parts;
}

}  // namespace

std::string Solution::BenchmarkId() const {
  std::vector<std::string> vehicles, costs;
  for (const SolutionTrajectory& t : trajectories) {
    vehicles.push_back("KS" + std::to_string(t.vehicle_type));
    costs.push_back(t.cost_function);
  }
  if (vehicles.empty()) {
    vehicles.push_back("KS2");
    costs.push_back("WX1");
  }
  return JoinIds(vehicles) + ":" + JoinIds(costs) + ":" + scenario_id + ":" + version;
}

std::string FileNamePart(std::string_view text) {
  std::string name(text);
  for (char& c : name) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_' ||
                      c == '.' || c == ':' || c == '[' || c == ']' || c == ',';
    if (!keep) c = '_';
  }
  return name;
}

std::string Solution::FileName() const {
  return "solution_" + FileNamePart(BenchmarkId()) + ".xml";
}

std::string WriteSolution(const Solution& solution) {
  pugi::xml_document doc;
  pugi::xml_node root = doc.append_child("CommonRoadSolution");
  root.append_attribute("benchmark_id") = solution.BenchmarkId().c_str();
  if (solution.computation_time) {
    root.append_attribute("computation_time") = Number(*solution.computation_time).c_str();
  }
  if (!solution.date.empty()) root.append_attribute("date") = solution.date.c_str();
  if (!solution.processor_name.empty()) {
    root.append_attribute("processor_name") = solution.processor_name.c_str();
  }
  for (const SolutionTrajectory& t : solution.trajectories) {
    pugi::xml_node trajectory = root.append_child("ksTrajectory");
    trajectory.append_attribute("planningProblem") = t.problem_id;
    for (const KsState& s : t.states) {
      pugi::xml_node state = trajectory.append_child("ksState");
      // commonroad-io's field order (XMLStateFields.KS).
      state.append_child("x").text() = Number(s.x).c_str();
      state.append_child("y").text() = Number(s.y).c_str();
      state.append_child("steeringAngle").text() = Number(s.steering_angle).c_str();
      state.append_child("velocity").text() = Number(s.velocity).c_str();
      state.append_child("orientation").text() = Number(s.orientation).c_str();
      state.append_child("time").text() = s.time_step;
    }
  }
  std::ostringstream out;
  doc.save(out, "  ", pugi::format_default | pugi::format_no_declaration);
  return "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n" + out.str();
}

Status SaveSolution(const Solution& solution, const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / solution.FileName()).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Status::Error(path + ": cannot open for writing");
  out << WriteSolution(solution);
  out.close();
  if (!out) return Status::Error(path + ": write error");
  return Status::Ok();
}

namespace {

Status ReadTrajectory(const XmlSource& src, const pugi::xml_node& node, SolutionTrajectory* out) {
  FRENETIC_CR_TRY(src.AttrInt(node, "planningProblem", &out->problem_id));
  std::set<int> steps;
  for (const pugi::xml_node& n : node.children()) {
    if (n.type() != pugi::node_element) continue;
    if (std::string_view(n.name()) != "ksState") {
      return src.Error(n, "a ksTrajectory holds only <ksState>s");
    }
    KsState& s = out->states.emplace_back();
    FRENETIC_CR_TRY(src.ChildNumber(n, "x", &s.x));
    FRENETIC_CR_TRY(src.ChildNumber(n, "y", &s.y));
    FRENETIC_CR_TRY(src.ChildNumber(n, "steeringAngle", &s.steering_angle));
    FRENETIC_CR_TRY(src.ChildNumber(n, "velocity", &s.velocity));
    FRENETIC_CR_TRY(src.ChildNumber(n, "orientation", &s.orientation));
    pugi::xml_node time;
    FRENETIC_CR_TRY(src.Child(n, "time", &time));
    FRENETIC_CR_TRY(src.Integer(time, &s.time_step));
    if (!steps.insert(s.time_step).second) {
      return src.Error(n, "time step " + std::to_string(s.time_step) + " repeated");
    }
  }
  if (out->states.empty()) return src.Error(node, "no <ksState>");
  std::sort(out->states.begin(), out->states.end(),
            [](const KsState& a, const KsState& b) { return a.time_step < b.time_step; });
  return Status::Ok();
}

}  // namespace

StatusOr<Solution> ParseSolution(std::string_view xml, std::string_view source) {
  const XmlSource src(xml, source);
  pugi::xml_document doc;
  FRENETIC_CR_TRY(src.Parse(&doc));
  const pugi::xml_node root = doc.document_element();
  if (!root) return Status::Error(src.source() + ":1: document: no root element");
  if (std::string_view(root.name()) != "CommonRoadSolution") {
    return src.Error(root, "the root element must be <CommonRoadSolution>");
  }
  Solution solution;
  std::string benchmark_id;
  FRENETIC_CR_TRY(src.AttrString(root, "benchmark_id", &benchmark_id));
  const std::vector<std::string> parts = SplitBenchmarkId(benchmark_id);
  if (parts.size() != 4 || parts[2].empty() || parts[3].empty()) {
    return src.Error(root, "benchmark_id '" + benchmark_id.substr(0, 80) +
                               "' is not <vehicle>:<cost>:<scenario>:<version>");
  }
  const std::vector<std::string> vehicles = SplitIds(parts[0]);
  const std::vector<std::string> costs = SplitIds(parts[1]);
  solution.scenario_id = parts[2];
  solution.version = parts[3];
  for (const std::string& v : vehicles) {
    if (v != "KS1" && v != "KS2" && v != "KS3") {
      return src.Error(root, "vehicle id '" + v.substr(0, 20) +
                                 "' is not supported (KS1, KS2 or KS3)");
    }
  }
  for (const std::string& c : costs) {
    if (!KnownCost(c)) return src.Error(root, "cost function id '" + c.substr(0, 20) + "' unknown");
  }
  if (const pugi::xml_attribute a = root.attribute("computation_time")) {
    double t = 0;
    FRENETIC_CR_TRY(src.AttrNumber(root, "computation_time", &t));
    solution.computation_time = t;
  }
  solution.date = root.attribute("date").value();
  solution.processor_name = root.attribute("processor_name").value();

  size_t index = 0;
  for (const pugi::xml_node& n : root.children()) {
    if (n.type() != pugi::node_element) continue;
    if (std::string_view(n.name()) != "ksTrajectory") {
      return src.Error(n, "trajectory type <" + std::string(n.name()).substr(0, 20) +
                              "> is not supported (ksTrajectory only)");
    }
    SolutionTrajectory& t = solution.trajectories.emplace_back();
    FRENETIC_CR_TRY(ReadTrajectory(src, n, &t));
    if (index < vehicles.size()) t.vehicle_type = vehicles[index].back() - '0';
    if (index < costs.size()) t.cost_function = costs[index];
    ++index;
  }
  if (solution.trajectories.empty()) return src.Error(root, "no <ksTrajectory>");
  if (vehicles.size() != index || costs.size() != index) {
    return src.Error(root, "benchmark_id lists " + std::to_string(vehicles.size()) +
                               " vehicle(s) and " + std::to_string(costs.size()) +
                               " cost function(s) for " + std::to_string(index) +
                               " trajectorie(s)");
  }
  return solution;
}

StatusOr<Solution> LoadSolution(const std::string& path) {
  StatusOr<std::string> text = ReadXmlFile(path);
  if (!text.ok()) return text.status();
  return ParseSolution(*text, path);
}

std::string PeekRootElementOf(std::string_view text) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  size_t at = 0;
  // Skips to just past `end`; false when it does not occur.
  auto skip_past = [&](std::string_view end) {
    const size_t found = text.find(end, at);
    if (found == std::string_view::npos) return false;
    at = found + end.size();
    return true;
  };
  while (true) {
    at = text.find('<', at);
    if (at == std::string_view::npos || at + 1 >= text.size()) return "";
    const std::string_view rest = text.substr(at);
    if (rest.substr(0, 2) == "<?") {
      if (!skip_past("?>")) return "";
    } else if (rest.substr(0, 4) == "<!--") {
      if (!skip_past("-->")) return "";
    } else if (rest.substr(0, 2) == "<!") {  // a doctype, with its internal subset if any
      const size_t bracket = text.find('[', at), close = text.find('>', at);
      if (bracket != std::string_view::npos && bracket < close && !skip_past("]")) return "";
      if (!skip_past(">")) return "";
    } else {
      const size_t end = rest.find_first_of(" \t\r\n/>", 1);
      if (end == std::string_view::npos) return "";
      return std::string(rest.substr(1, end - 1));
    }
  }
}

std::string PeekRootElement(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  return PeekRootElementOf(head);
}

std::string CurrentDate() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%S", &local);
  return buffer;
}

std::string ProcessorName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(colon + 1);
    for (const char* junk : {"(R)", "(TM)"}) {
      for (size_t at; (at = name.find(junk)) != std::string::npos;) {
        name.erase(at, std::string_view(junk).size());
      }
    }
    const size_t first = name.find_first_not_of(' ');
    return first == std::string::npos ? "" : name.substr(first);
  }
  return "";
}

}  // namespace frenetic::commonroad
