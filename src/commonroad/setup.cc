#include "frenetic/commonroad/setup.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "frenetic/commonroad/runner.h"

namespace frenetic::commonroad {

StatusOr<std::vector<std::string>> ScenarioFiles(const std::vector<std::string>& paths) {
  std::vector<std::string> out;
  for (const std::string& p : paths) {
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec)) {
      std::vector<std::string> dir;
      for (const auto& e : std::filesystem::directory_iterator(p, ec)) {
        if (e.path().extension() == ".xml") dir.push_back(e.path().string());
      }
      if (ec) return Status::Error(p + ": cannot list the directory: " + ec.message());
      std::sort(dir.begin(), dir.end());
      out.insert(out.end(), dir.begin(), dir.end());
    } else if (std::filesystem::exists(p, ec)) {
      out.push_back(p);
    } else {
      return Status::Error(p + ": no such file or directory");
    }
  }
  if (out.empty()) return Status::Error("no scenario files (*.xml) in the paths given");
  return out;
}

std::string DefaultOverlayPath() {
  return std::string(FRENETIC_SOURCE_DIR "/") + kCommonRoadConfig;
}

StatusOr<plan::PlannerConfig> LoadBaseConfig(const std::string& config_path,
                                             const std::string& overlay_path) {
  auto base = plan::PlannerConfig::Load(config_path.empty() ? plan::PlannerConfig::DefaultPath()
                                                            : config_path);
  if (!base.ok()) return base.status();
  if (Status st = base->OverlayFile(overlay_path.empty() ? DefaultOverlayPath() : overlay_path);
      !st.ok()) {
    return st;
  }
  return base;
}

}  // namespace frenetic::commonroad
