// The search: NLopt on the unit box, a global derivative-free phase then a local one from its
// best point, every evaluation logged; a resumed run answers logged points from the log. Both
// phases are deterministic given NLopt's seed and the answers, so a resumed run retraces the
// interrupted one exactly (the JSON numbers round-trip bit for bit).
#include <nlopt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

#include "frenetic/json_text.h"
#include "frenetic/tune/tuner.h"

namespace frenetic::tune {
namespace {

using Clock = std::chrono::steady_clock;

const char* SetName(SeedSet set) { return set == SeedSet::kTrain ? "train" : "holdout"; }

// Logged evaluations by (seed set, parameter values).
using Cache = std::map<std::pair<std::string, std::vector<double>>, Metrics>;

StatusOr<Cache> ReadLog(const std::string& path, const Suite& suite) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open the resume log");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  Cache cache;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string where = path + ":" + std::to_string(i + 1);
    nlohmann::json j = nlohmann::json::parse(lines[i], nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) {
      if (i + 1 == lines.size()) break;  // cut short by the interruption
      return Status::Error(where + ": not a JSON object");
    }
    try {
      const auto keys = j.at("keys").get<std::vector<std::string>>();
      if (keys.size() != suite.params.size()) {
        return Status::Error(where + ": logged for other parameters than " + suite.source);
      }
      for (std::size_t k = 0; k < keys.size(); ++k) {
        if (keys[k] != suite.params[k].key) {
          return Status::Error(where + ": logged for parameter '" + keys[k] + "', the suite has '" +
                               suite.params[k].key + "'");
        }
      }
      auto metrics = Metrics::FromJson(j.at("components"));
      if (!metrics.ok()) return Status::Error(where + ": " + metrics.message());
      cache[{j.at("set").get<std::string>(), j.at("values").get<std::vector<double>>()}] = *metrics;
    } catch (const nlohmann::json::exception& e) {
      return Status::Error(where + ": " + e.what());
    }
  }
  return cache;
}

class Search {
 public:
  Search(const Suite& suite, const TuneOptions& options, Evaluator& evaluator, Cache replay,
         std::ofstream* log)
      : suite_(suite),
        options_(options),
        evaluator_(evaluator),
        replay_(std::move(replay)),
        log_(log),
        budget_(options.budget > 0 ? options.budget : suite.search.budget),
        start_time_(Clock::now()) {}

  int budget() const { return budget_; }
  int done() const { return done_; }
  int replayed() const { return replayed_; }
  const Status& status() const { return status_; }
  int best_index() const { return best_index_; }
  const std::vector<double>& best_x() const { return best_x_; }
  const Metrics& best() const { return best_; }

  std::vector<double> Values(const std::vector<double>& x) const {
    std::vector<double> v(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) v[i] = suite_.params[i].FromUnit(x[i]);
    return v;
  }

  // One evaluation: from memory (this run or the resume log) or by driving the episodes.
  StatusOr<Metrics> Evaluate(const std::vector<double>& values, SeedSet set,
                             const std::string& phase, const std::vector<double>* x,
                             bool* was_replayed) {
    const auto key = std::make_pair(std::string(SetName(set)), values);
    Metrics m;
    *was_replayed = false;
    if (auto it = memo_.find(key); it != memo_.end()) {
      m = it->second;
      *was_replayed = replay_.count(key) > 0;
    } else if (auto r = replay_.find(key); r != replay_.end()) {
      m = r->second;
      *was_replayed = true;
    } else {
      auto fresh = evaluator_.Evaluate(values, set);
      if (!fresh.ok()) return fresh.status();
      m = *fresh;
      ++run_;
    }
    memo_[key] = m;
    Log(values, set, phase, x, m);
    return m;
  }

  // The NLopt objective over the unit box.
  double Objective(const double* x_raw, unsigned n, nlopt_opt opt) {
    if (!status_.ok() || done_ >= budget_) {
      nlopt_force_stop(opt);
      return best_index_ >= 0 ? best_.objective : 0;
    }
    std::vector<double> x(x_raw, x_raw + n);
    bool was_replayed = false;
    auto m = Evaluate(Values(x), SeedSet::kTrain, "search", &x, &was_replayed);
    if (!m.ok()) {
      status_ = m.status();
      nlopt_force_stop(opt);
      return 0;
    }
    Consider(x, *m, done_);
    ++done_;
    if (was_replayed) ++replayed_;
    if (done_ >= budget_) nlopt_force_stop(opt);
    Report();
    return m->objective;
  }

  // Keeps the first of equal bests, so ties break by evaluation order.
  void Consider(const std::vector<double>& x, const Metrics& m, int index) {
    if (best_index_ < 0 || m.objective < best_.objective) {
      best_ = m;
      best_x_ = x;
      best_index_ = index;
    }
  }

  // Runs one NLopt phase from x0 for at most `evals` evaluations.
  void RunPhase(const std::string& algorithm_name, std::vector<double>* x0, int evals) {
    if (evals <= 0 || !status_.ok()) return;
    const unsigned n = static_cast<unsigned>(x0->size());
    std::string name = algorithm_name;
    nlopt_algorithm algorithm = nlopt_algorithm_from_string(name.c_str());
    if (static_cast<int>(algorithm) < 0) {
      status_ = Status::Error(suite_.source + ": unknown NLopt algorithm '" + name + "'");
      return;
    }
    if (n == 1 && (algorithm == NLOPT_LN_BOBYQA || algorithm == NLOPT_LN_NEWUOA_BOUND)) {
      // Both need n >= 2; on one parameter a simplex does the same job.
      spdlog::warn("{} needs two or more parameters; using LN_NELDERMEAD", name);
      algorithm = NLOPT_LN_NELDERMEAD;
    }
    nlopt_opt opt = nlopt_create(algorithm, n);
    if (opt == nullptr) {
      status_ = Status::Error(suite_.source + ": NLopt cannot create '" + name + "'");
      return;
    }
    nlopt_srand(suite_.search.seed);
    const std::vector<double> lo(n, 0.0), hi(n, 1.0), step(n, suite_.search.initial_step);
    nlopt_set_lower_bounds(opt, lo.data());
    nlopt_set_upper_bounds(opt, hi.data());
    nlopt_set_initial_step(opt, step.data());
    nlopt_set_maxeval(opt, evals);
    struct Ctx {
      Search* self;
      nlopt_opt opt;
    } ctx{this, opt};
    nlopt_set_min_objective(
        opt,
        [](unsigned n, const double* x, double* grad, void* data) -> double {
          (void)grad;  // derivative-free methods only
          auto* c = static_cast<Ctx*>(data);
          return c->self->Objective(x, n, c->opt);
        },
        &ctx);
    double f = 0;
    const nlopt_result r = nlopt_optimize(opt, x0->data(), &f);
    if (r < 0 && r != NLOPT_FORCED_STOP && r != NLOPT_ROUNDOFF_LIMITED && status_.ok()) {
      status_ = Status::Error(suite_.source + ": NLopt " + name + " failed: " +
                              nlopt_result_to_string(r));
    }
    nlopt_destroy(opt);
  }

 private:
  void Log(const std::vector<double>& values, SeedSet set, const std::string& phase,
           const std::vector<double>* x, const Metrics& m) {
    if (log_ == nullptr) return;
    nlohmann::json keys = nlohmann::json::array(), params = nlohmann::json::object();
    for (std::size_t i = 0; i < values.size(); ++i) {
      keys.push_back(suite_.params[i].key);
      params[suite_.params[i].key] = values[i];
    }
    nlohmann::json j = {{"i", logged_++},       {"phase", phase},
                        {"set", SetName(set)},  {"keys", keys},
                        {"values", values},     {"params", params},
                        {"objective", m.objective}, {"components", m.ToJson()}};
    if (x != nullptr) j["x"] = *x;
    *log_ << JsonText(j) << "\n";
    log_->flush();  // a kill loses at most the line being written
  }

  void Report() {
    if (!options_.progress) return;
    Progress p;
    p.done = done_;
    p.budget = budget_;
    p.replayed = replayed_;
    p.best = best_.objective;
    p.elapsed_s = std::chrono::duration<double>(Clock::now() - start_time_).count();
    const int remaining = budget_ - done_;
    p.remaining_s = run_ > 0 ? p.elapsed_s / run_ * remaining : 0;
    options_.progress(p);
  }

  const Suite& suite_;
  const TuneOptions& options_;
  Evaluator& evaluator_;
  Cache replay_, memo_;
  std::ofstream* log_;
  int budget_;
  Clock::time_point start_time_;
  Status status_;
  int done_ = 0, replayed_ = 0, run_ = 0, logged_ = 0;
  int best_index_ = -1;
  std::vector<double> best_x_;
  Metrics best_;
};

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

StatusOr<TuneResult> Tune(const Suite& suite, const TuneOptions& options, Evaluator& evaluator) {
  // Whatever happens, release the worker ranks.
  struct StopGuard {
    Evaluator& e;
    ~StopGuard() { e.Stop(); }
  } guard{evaluator};

  Cache replay;
  if (!options.resume_path.empty()) {
    auto read = ReadLog(options.resume_path, suite);
    if (!read.ok()) return read.status();
    replay = std::move(*read);
    spdlog::info("resuming: {} logged evaluations in {}", replay.size(), options.resume_path);
  }
  // Read before opening: the log may be the resume file, rewritten in replay order.
  std::ofstream log_file;
  if (!options.log_path.empty()) {
    log_file.open(options.log_path, std::ios::trunc);
    if (!log_file) return Status::Error(options.log_path + ": cannot write the log");
  }
  Search search(suite, options, evaluator, std::move(replay),
                options.log_path.empty() ? nullptr : &log_file);

  const std::vector<double> start_values = evaluator.start_values();
  bool replayed = false;
  auto start_train = search.Evaluate(start_values, SeedSet::kTrain, "start_train", nullptr,
                                     &replayed);
  if (!start_train.ok()) return start_train.status();

  // The local phase starts from the global phase's best point; without a global phase, from
  // the start configuration (its nearest point in the box).
  std::vector<double> x0;
  for (std::size_t i = 0; i < suite.params.size(); ++i) {
    x0.push_back(suite.params[i].ToUnit(start_values[i]));
  }
  const int global_evals =
      static_cast<int>(std::lround(search.budget() * suite.search.global_fraction));
  std::vector<double> x = x0;
  search.RunPhase(suite.search.global_algorithm, &x, global_evals);
  if (search.best_index() >= 0) x = search.best_x();
  search.RunPhase(suite.search.local_algorithm, &x, search.budget() - search.done());
  if (!search.status().ok()) return search.status();
  if (search.best_index() < 0) return Status::Error(suite.source + ": the search evaluated nothing");

  TuneResult result;
  result.best_x = search.best_x();
  result.best_evaluation = search.best_index();
  result.evaluations = search.done();
  result.replayed = search.replayed();
  std::vector<double> tuned_values = search.Values(result.best_x);
  result.tuned_train = search.best();
  // The search never beat the start configuration: the start stays (a tuner returns nothing
  // worse than what it was given).
  result.start_kept = start_train->objective <= search.best().objective;
  if (result.start_kept) {
    tuned_values = start_values;
    result.best_x = x0;
    result.best_evaluation = 0;
    result.tuned_train = *start_train;
  }
  for (std::size_t i = 0; i < suite.params.size(); ++i) {
    result.params.push_back({suite.params[i].key, start_values[i], tuned_values[i]});
  }
  result.start_train = *start_train;
  result.commonroad = suite.kind == SuiteKind::kCommonRoad;
  if (result.commonroad) result.cost_function = suite.commonroad.cost_function;
  result.has_holdout = evaluator.episodes(SeedSet::kHoldout) > 0;
  if (result.has_holdout) {
    auto start_holdout =
        search.Evaluate(start_values, SeedSet::kHoldout, "start_holdout", nullptr, &replayed);
    if (!start_holdout.ok()) return start_holdout.status();
    auto tuned_holdout =
        search.Evaluate(tuned_values, SeedSet::kHoldout, "tuned_holdout", nullptr, &replayed);
    if (!tuned_holdout.ok()) return tuned_holdout.status();
    result.start_holdout = *start_holdout;
    result.tuned_holdout = *tuned_holdout;
  }
  auto config = evaluator.ConfigFor(tuned_values);
  if (!config.ok()) return config.status();
  result.tuned_yaml = config->ToYaml();
  return result;
}

nlohmann::json TuneResult::ToJson() const {
  nlohmann::json params_j = nlohmann::json::array();
  for (const TunedValue& p : params) {
    params_j.push_back({{"key", p.key}, {"start", p.start}, {"tuned", p.tuned}});
  }
  return {{"evaluations", evaluations},
          {"replayed", replayed},
          {"best_evaluation", best_evaluation},
          {"start_kept", start_kept},
          {"best_x", best_x},
          {"params", params_j},
          {"train", {{"default", start_train.ToJson()}, {"tuned", tuned_train.ToJson()}}},
          {"holdout", has_holdout ? nlohmann::json{{"default", start_holdout.ToJson()},
                                                   {"tuned", tuned_holdout.ToJson()}}
                                  : nlohmann::json(nullptr)}};
}

std::string TuneResult::ToTable() const {
  std::ostringstream os;
  os << "parameter                         start       tuned\n";
  for (const TunedValue& p : params) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%-30s %10.4g  %10.4g\n", p.key.c_str(), p.start, p.tuned);
    os << buf;
  }
  if (commonroad) {
    os << "\nfiles     config    objective  solved     mean " << cost_function << " (solved)\n";
    auto row = [&](const char* files, const char* which, const Metrics& m) {
      char buf[160];
      const std::string solved = std::to_string(m.solved) + "/" + std::to_string(m.problems);
      std::snprintf(buf, sizeof buf, "%-9s %-8s %10s  %-9s  %10s\n", files, which,
                    Fixed(m.objective, 4).c_str(), solved.c_str(), Fixed(m.mean_cost, 2).c_str());
      os << buf;
    };
    row("train", "default", start_train);
    row("train", "tuned", tuned_train);
    if (has_holdout) {
      row("held-out", "default", start_holdout);
      row("held-out", "tuned", tuned_holdout);
    }
  } else {
    os << "\nseeds     config    objective  incidents/100mi  avg mph  comfort (m^2/s^6)\n";
    auto row = [&](const char* seeds, const char* which, const Metrics& m) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%-9s %-8s %10s %16s %8s %18s\n", seeds, which,
                    Fixed(m.objective, 3).c_str(), Fixed(m.incidents_per_100_miles, 1).c_str(),
                    Fixed(m.avg_speed_mph, 2).c_str(), Fixed(m.mean_squared_jerk, 3).c_str());
      os << buf;
    };
    row("train", "default", start_train);
    row("train", "tuned", tuned_train);
    row("held-out", "default", start_holdout);
    row("held-out", "tuned", tuned_holdout);
  }
  if (start_kept) os << "no search point beat the start: it is kept\n";
  os << "(" << evaluations << " evaluations, best #" << best_evaluation;
  if (replayed > 0) os << ", " << replayed << " replayed from the log";
  os << ")\n";
  return os.str();
}

}  // namespace frenetic::tune
