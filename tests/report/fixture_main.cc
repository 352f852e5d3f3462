// Writes synthetic drive records and their report pages for the browser test:
//   frenetic_report_fixture OUT_DIR [--large N]
// OUT_DIR/run.{jsonl,html} (a short drive), OUT_DIR/incident.{jsonl,html} (with a collision),
// OUT_DIR/commonroad.{jsonl,html} (a CommonRoad run's header), and with --large N also
// OUT_DIR/large.{jsonl,html} (N exchanges) to time the page's opening.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "frenetic/record/reader.h"
#include "frenetic/report/page.h"
#include "record/synthetic_record.h"

namespace {

int Write(const std::string& dir, const std::string& name,
          const frenetic::record::testing::SyntheticOptions& options) {
  const std::string jsonl = dir + "/" + name + ".jsonl";
  const std::string html = dir + "/" + name + ".html";
  if (auto s =
          frenetic::report::WriteFile(jsonl, frenetic::record::testing::SyntheticRecord(options));
      !s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 1;
  }
  auto run = frenetic::record::ReadRecordFile(jsonl);
  if (!run.ok()) {
    std::fprintf(stderr, "%s\n", run.message().c_str());
    return 1;
  }
  if (auto s = frenetic::report::WriteFile(html, frenetic::report::RenderPage(*run, name + ".jsonl"));
      !s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::string(argv[2]) == "--large")) {
    std::fprintf(stderr, "usage: frenetic_report_fixture OUT_DIR [--large N]\n");
    return 2;
  }
  const std::string dir = argv[1];
  frenetic::record::testing::SyntheticOptions options;
  if (Write(dir, "run", options) != 0) return 1;
  options.incident = true;
  if (Write(dir, "incident", options) != 0) return 1;
  {
    frenetic::record::testing::SyntheticOptions cr;
    cr.commonroad = true;
    if (Write(dir, "commonroad", cr) != 0) return 1;
  }
  if (argc == 4) {
    options.exchanges = std::atoi(argv[3]);
    options.incident_at = options.exchanges / 2;
    if (options.exchanges < 1) {
      std::fprintf(stderr, "--large: N must be >= 1\n");
      return 2;
    }
    if (Write(dir, "large", options) != 0) return 1;
  }
  return 0;
}
