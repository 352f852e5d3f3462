#include "record/candidate_sampler.h"

#include <utility>

namespace frenetic::record {

void CandidateSampler::Add(CycleCandidates cycle, bool incident, bool lane_change) {
  const int k = cycle.exchange;
  const bool pin_lane = lane_change && !incident && lane_pins_ < max_cycles_;
  if (pin_lane && pinned_.insert(k).second) ++lane_pins_;
  if (pinned_.count(k) != 0 || k % stride_ == 0) kept_[k] = cycle;
  recent_.push_back(std::move(cycle));
  if (static_cast<int>(recent_.size()) > kCyclesBeforeIncident + 1) recent_.pop_front();
  if (incident) PinRecent();
  Thin();
}

void CandidateSampler::AddWithoutCandidates(bool incident) {
  if (incident) PinRecent();
}

std::vector<CycleCandidates> CandidateSampler::Take() {
  std::vector<CycleCandidates> out;
  out.reserve(kept_.size());
  for (auto& [exchange, cycle] : kept_) out.push_back(std::move(cycle));
  kept_.clear();
  pinned_.clear();
  recent_.clear();
  return out;
}

void CandidateSampler::PinRecent() {
  // Newest first: the incident's own cycle matters most.
  for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
    const CycleCandidates& c = *it;
    if (incident_pins_ >= max_cycles_) break;
    if (pinned_.insert(c.exchange).second) {
      ++incident_pins_;
      kept_[c.exchange] = c;
    }
  }
}

void CandidateSampler::Thin() {
  while (static_cast<int>(kept_.size() - pinned_.size()) > max_cycles_) {
    stride_ *= 2;
    for (auto it = kept_.begin(); it != kept_.end();) {
      if (it->first % stride_ != 0 && pinned_.count(it->first) == 0) {
        it = kept_.erase(it);
      } else {
        ++it;
      }
    }
  }
}

}  // namespace frenetic::record
