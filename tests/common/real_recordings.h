// The real Unity recordings (shared/realdata/telemetry) and the Udacity world, loaded once per
// test suite for the tests that read them; each test is skipped when the shared data is absent.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "frenetic/eval/fidelity.h"
#include "frenetic/sim/world.h"

namespace frenetic::sim::testing {

inline const std::string kShared = FRENETIC_SHARED_DIR;
inline const std::string kRecordings = kShared + "/realdata/telemetry";
inline const std::string kMap = kShared + "/data/highway_map.csv";

class RealRecordingsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(kRecordings) || !std::filesystem::exists(kMap)) return;
    auto recs = LoadRecordings(kRecordings);
    auto world = LoadWorld(kMap);
    if (!recs.ok() || !world.ok()) return;
    recordings_ = new std::vector<Recording>(std::move(*recs));
    world_ = new std::shared_ptr<const World>(*world);
  }
  static void TearDownTestSuite() {
    delete recordings_;
    delete world_;
    recordings_ = nullptr;
    world_ = nullptr;
  }
  void SetUp() override {
    if (recordings_ == nullptr) {
      GTEST_SKIP() << "real recordings or map not found under " << kShared
                   << " (realdata/telemetry, data/highway_map.csv)";
    }
  }
  static inline std::vector<Recording>* recordings_ = nullptr;
  static inline std::shared_ptr<const World>* world_ = nullptr;
};

}  // namespace frenetic::sim::testing
