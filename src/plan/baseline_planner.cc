// The `baseline` planner: the seeds' Udacity walkthrough planner, kept as a reference. States
// Drive / Follow / Overtake; speed ramped by a fixed step per cycle; the path is a spline through
// the last two path points and anchors 30/60/90 m ahead in the target lane, in car coordinates
// (Eigen's spline module), filled up to a fixed number of points.
#include <algorithm>
#include <cmath>
#include <unsupported/Eigen/Splines>

#include "frenetic/plan/planner_config.h"
#include "frenetic/plan/search_planner.h"
#include "frenetic/units.h"
#include "plan/predictor.h"
#include "plan/predictor_options.h"

namespace frenetic::plan {
namespace {


bool Finite(double v) { return std::isfinite(v); }

class BaselinePlanner : public Planner {
 public:
  enum class State { kDrive, kFollow, kOvertake };

  BaselinePlanner(const PlannerConfig& config, std::shared_ptr<const map::ReferenceLine> line)
      : line_(std::move(line)) {
    follow_distance_ = config.value("baseline.follow_distance");
    ahead_free_ = config.value("baseline.ahead_free");
    behind_free_ = config.value("baseline.behind_free");
    step_ = config.value("baseline.speed_step_mph") * units::kMphToMps;
    max_speed_ = config.value("baseline.max_speed_mph") * units::kMphToMps;
    points_ = std::max(kMinPathPoints, config.int_value("baseline.path_points"));
    lane_width_ = config.value("road.lane_width");
    num_lanes_ = config.int_value("road.num_lanes");
    PredictorOptions po = BasicPredictorOptions(config);
    predictor_ = MakeConstantVelocityPredictor(line_, po);
    Reset();
  }

  std::string_view name() const override { return "baseline"; }

  void Reset() override {
    ref_vel_ = 0;
    lane_ = -1;
    state_ = State::kDrive;
    last_x_ = last_y_ = last_yaw_ = NAN;
    predictor_->Reset();
  }

  const PlanResult& Plan(const Telemetry& t) override {
    result_.status = PlanStatus::kOk;
    result_.x.clear();
    result_.y.clear();
    result_.summary = PlanSummary();
    bool invalid = false;
    double cx = t.x, cy = t.y, cyaw = t.yaw;
    if (!Finite(cx) || !Finite(cy) || !Finite(cyaw) || std::abs(cx) > 1e6 ||
        std::abs(cy) > 1e6) {
      invalid = true;
      if (Finite(last_x_)) {
        cx = last_x_;
        cy = last_y_;
        cyaw = last_yaw_;
      } else {
        const map::CartesianPose p = line_->ToCartesian(0, 1.5 * lane_width_);
        cx = p.x;
        cy = p.y;
        cyaw = p.heading;
      }
    }
    // The previous path, if usable (equal lengths, finite).
    bool prev_ok = t.previous_path_x.size() == t.previous_path_y.size();
    for (size_t i = 0; prev_ok && i < t.previous_path_x.size(); ++i) {
      prev_ok = Finite(t.previous_path_x[i]) && Finite(t.previous_path_y[i]) &&
                std::abs(t.previous_path_x[i]) < 1e6 && std::abs(t.previous_path_y[i]) < 1e6;
    }
    invalid = invalid || !prev_ok;
    const int prev_size =
        prev_ok ? std::min<int>(static_cast<int>(t.previous_path_x.size()), points_ - 1) : 0;

    const map::FrenetPoint ego = line_->ToFrenet(cx, cy);
    if (lane_ < 0) lane_ = LaneOf(ego.d);
    double end_s = ego.s;
    if (prev_size > 0) {
      end_s = line_->ToFrenet(t.previous_path_x[prev_size - 1], t.previous_path_y[prev_size - 1],
                              ego.s)
                  .s;
    }
    const double horizon = prev_size * kTickSeconds;

    // Gaps per lane at the end of the previous path: free room ahead and behind.
    // The seeds' planner looks at speeds only (constant velocity): no elapsed time needed.
    predictor_->Observe(t.sensor_fusion, end_s, 0.0);
    double ahead[8], behind[8], lead_speed[8];
    for (int l = 0; l < num_lanes_ && l < 8; ++l) {
      ahead[l] = behind[l] = 1e9;
      lead_speed[l] = max_speed_;
    }
    const auto cars = predictor_->cars();
    for (int i = 0; i < static_cast<int>(cars.size()); ++i) {
      const int l = static_cast<int>(std::floor(cars[i].d / lane_width_));
      if (l < 0 || l >= num_lanes_ || l >= 8) continue;
      const double s = predictor_->Predict(i, horizon).s;  // relative to end_s
      if (s >= 0 && s < ahead[l]) {
        ahead[l] = s;
        lead_speed[l] = cars[i].v_s;
      }
      if (s < 0 && -s < behind[l]) behind[l] = -s;
    }
    // State machine.
    const int ego_lane = LaneOf(ego.d);
    if (state_ == State::kOvertake) {
      const double centre = (lane_ + 0.5) * lane_width_;
      if (std::abs(ego.d - centre) < 0.5) state_ = State::kDrive;
    }
    bool too_close = false;
    if (state_ != State::kOvertake) {
      too_close = ahead[lane_] < follow_distance_;
      state_ = too_close ? State::kFollow : State::kDrive;
      if (too_close && ego_lane == lane_) {
        int best = -1;
        double best_room = ahead[lane_];
        for (int l = lane_ - 1; l <= lane_ + 1; l += 2) {
          if (l < 0 || l >= num_lanes_) continue;
          if (ahead[l] >= ahead_free_ && behind[l] >= behind_free_ && ahead[l] > best_room) {
            best_room = ahead[l];
            best = l;
          }
        }
        if (best >= 0) {
          lane_ = best;
          state_ = State::kOvertake;
        }
      }
    }
    if (state_ == State::kFollow && ref_vel_ > lead_speed[lane_]) {
      ref_vel_ -= step_;
    } else if (state_ != State::kFollow && ref_vel_ < max_speed_ - step_) {
      ref_vel_ += step_;
    } else if (state_ == State::kFollow && ahead[lane_] < 0.5 * follow_distance_) {
      ref_vel_ -= step_;
    }
    ref_vel_ = std::clamp(ref_vel_, 0.0, max_speed_);

    // Reference pose: the end of the previous path, or the car.
    double ref_x = cx, ref_y = cy, ref_yaw = cyaw;
    double px[5], py[5];
    int n = 0;
    if (prev_size < 2) {
      px[n] = cx - std::cos(cyaw);
      py[n++] = cy - std::sin(cyaw);
      px[n] = cx;
      py[n++] = cy;
    } else {
      ref_x = t.previous_path_x[prev_size - 1];
      ref_y = t.previous_path_y[prev_size - 1];
      const double bx = t.previous_path_x[prev_size - 2], by = t.previous_path_y[prev_size - 2];
      ref_yaw = std::atan2(ref_y - by, ref_x - bx);
      if (!Finite(ref_yaw) || (ref_x == bx && ref_y == by)) ref_yaw = cyaw;
      px[n] = bx;
      py[n++] = by;
      px[n] = ref_x;
      py[n++] = ref_y;
    }
    const double target_d = (lane_ + 0.5) * lane_width_;
    for (double ahead_m : {30.0, 60.0, 90.0}) {
      const map::CartesianPose p = line_->ToCartesian(end_s + ahead_m, target_d);
      px[n] = p.x;
      py[n++] = p.y;
    }
    // To car coordinates; the spline needs strictly increasing x.
    Eigen::RowVectorXd xs(n), ys(n);
    int m = 0;
    const double c = std::cos(-ref_yaw), s = std::sin(-ref_yaw);
    for (int i = 0; i < n; ++i) {
      const double dx = px[i] - ref_x, dy = py[i] - ref_y;
      const double lx = dx * c - dy * s, ly = dx * s + dy * c;
      if (m > 0 && !(lx > xs[m - 1] + 1e-3)) continue;
      xs[m] = lx;
      ys[m] = ly;
      ++m;
    }
    for (int i = 0; i < prev_size; ++i) {
      result_.x.push_back(t.previous_path_x[i]);
      result_.y.push_back(t.previous_path_y[i]);
    }
    const int needed = points_ - prev_size;
    if (m >= 2) {
      // y(x) through the anchors: Eigen's spline interpolation with the (normalised) x values
      // as knot parameters.
      const double x0 = xs[0], span = xs[m - 1] - xs[0];
      Eigen::RowVectorXd u = (xs.head(m).array() - x0) / span;
      Eigen::Matrix<double, 1, Eigen::Dynamic> yv = ys.head(m);
      const auto spline = Eigen::SplineFitting<Eigen::Spline<double, 1>>::Interpolate(
          yv, std::min(3, m - 1), u);
      const double target_x = std::min(30.0, xs[m - 1]);
      const double target_y = spline((target_x - x0) / span)(0);
      const double dist = std::hypot(target_x, target_y);
      const double v = std::max(ref_vel_, 1e-3);
      const double dx = target_x / (dist / (kTickSeconds * v));
      double lx = 0;
      for (int i = 0; i < needed; ++i) {
        lx += dx;
        const double uu = std::clamp((lx - x0) / span, 0.0, 1.0);
        const double ly = spline(uu)(0);
        result_.x.push_back(ref_x + lx * std::cos(ref_yaw) - ly * std::sin(ref_yaw));
        result_.y.push_back(ref_y + lx * std::sin(ref_yaw) + ly * std::cos(ref_yaw));
      }
    }
    // Whatever happened, send at least kMinPathPoints finite points.
    for (size_t i = 0; i < result_.x.size(); ++i) {
      if (!Finite(result_.x[i]) || !Finite(result_.y[i])) {
        result_.x[i] = i > 0 ? result_.x[i - 1] : ref_x;
        result_.y[i] = i > 0 ? result_.y[i - 1] : ref_y;
      }
    }
    while (static_cast<int>(result_.x.size()) < points_) {
      result_.x.push_back(result_.x.empty() ? ref_x : result_.x.back());
      result_.y.push_back(result_.y.empty() ? ref_y : result_.y.back());
    }
    if (!invalid) {
      last_x_ = cx;
      last_y_ = cy;
      last_yaw_ = cyaw;
    }
    result_.summary.winner_lane = lane_;
    result_.summary.winner_end_speed = ref_vel_;
    result_.summary.points_kept = prev_size;
    result_.status = invalid ? PlanStatus::kInvalidInput : PlanStatus::kOk;
    return result_;
  }

 private:
  // The lane of a lateral offset, clamped in double first: a hostile pose far off the road must
  // not overflow the int.
  int LaneOf(double d) const {
    const double lane = std::floor(d / lane_width_);
    return static_cast<int>(std::clamp(std::isfinite(lane) ? lane : 0.0, 0.0, num_lanes_ - 1.0));
  }

  std::shared_ptr<const map::ReferenceLine> line_;
  std::unique_ptr<Predictor> predictor_;
  double follow_distance_, ahead_free_, behind_free_, step_, max_speed_, lane_width_;
  int points_, num_lanes_;
  double ref_vel_ = 0;
  int lane_ = -1;
  State state_ = State::kDrive;
  double last_x_ = NAN, last_y_ = NAN, last_yaw_ = NAN;
  PlanResult result_;
};

}  // namespace

std::unique_ptr<Planner> MakeBaselinePlanner(const PlannerConfig& config,
                                             std::shared_ptr<const map::ReferenceLine> line) {
  return std::make_unique<BaselinePlanner>(config, std::move(line));
}

}  // namespace frenetic::plan
