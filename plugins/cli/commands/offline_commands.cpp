// The commands that compute without DDS: eval (score an estimate CSV against a truth CSV) and
// accuracy (many seeds of scenarios through the offline stack, as a markdown table).
#include <fstream>
#include <iostream>
#include <sstream>

#include "beaconloc/core/limits.hpp"
#include "command.hpp"
#include "estimator_plugins.hpp"
#include "number_options.hpp"
#include "offline_run.hpp"
#include "options.hpp"
#include "pipeline.hpp"
#include "sim/faults.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc::cli {
namespace {

constexpr bool kOpen = true;         // (min, max]: the option must be > min
constexpr double kMaxDelayMs = 1e4;  // --delay-ms of accuracy runs

class EvalCommand : public Command {
 public:
  explicit EvalCommand(CLI::App& app)
      : Command(app.add_subcommand("eval", "score an estimate CSV against a truth CSV: metrics.json and plots")) {
    app_->add_option("--truth", truth_file_, "truth CSV (stamp_ns,x_m,y_m,yaw_rad)")
        ->required()
        ->check(CLI::ExistingFile);
    app_->add_option("--estimate", estimate_file_, "estimate CSV written by run or demo")
        ->required()
        ->check(CLI::ExistingFile);
    app_->add_option("--out", out_dir_, "output directory")->required();
    app_->add_option("--beacons", beacons_file_, "beacons CSV to draw (beacon_id,x_m,y_m,z_m)")
        ->check(CLI::ExistingFile);
    app_->add_option("--max-truth-gap-s", max_truth_gap_s_, "interpolate truth over gaps up to this long")
        ->transform(real_in(0.0, 3600.0, kOpen));
  }
  bool runs_participants() const override { return false; }
  int execute() override {
    const Metrics m = evaluate_files(truth_file_, estimate_file_, out_dir_, beacons_file_, max_truth_gap_s_);
    std::cout << format_metrics(m) << "\nwrote " << out_dir_ << "/metrics.json, trajectory.svg, error.svg\n";
    return m.samples ? 0 : 1;
  }

 private:
  std::string truth_file_, estimate_file_, out_dir_, beacons_file_;
  double max_truth_gap_s_ = 0.5;
};

class AccuracyCommand : public Command {
 public:
  explicit AccuracyCommand(CLI::App& app)
      : Command(app.add_subcommand(
            "accuracy",
            "accuracy over seeds, without DDS: a markdown table of mean and spread per scenario and estimator")) {
    app_->add_option("--scenario", scenarios_, "scenario YAML (repeatable)")->required()->check(CLI::ExistingFile);
    app_->add_option("--estimator", estimators_, "estimator (repeatable; default range_ekf)");
    estimator_plugin_option_set(estimator_plugins_).add_to(app_);
    app_->add_option("--seeds", seeds_, "number of seeds")->transform(whole_in(1, 1000));
    app_->add_option("--first-seed", first_seed_, "first seed")->transform(any_unsigned());
    app_->add_option("--settle-s", settle_s_, "seconds after the first pose not scored")
        ->transform(real_in(0.0, kMaxDurationS));
    app_->add_option("--param", parameters_, "estimator parameter NAME=VALUE for every estimator");
    app_->add_option("--odometry-k-v-m", odometry_k_v_m_,
                     "replace the scenarios' odometry noise k_v (sigma_v^2 = k_v |v| / dT per wheel)")
        ->transform(real_in(0.0, 1.0));
    app_->add_option("--table", table_,
                     "pose: E_p, E_phi, E_S, NEES (seed 000 Table II); distance: mean, std, RMSE, max of the "
                     "position error and the association rates (seed 001 Tables 4-7); path: the path error's std and "
                     "max (seed 002 Sec. 4)")
        ->check(CLI::IsMember({"pose", "distance", "path"}));
    app_->add_option("--out", out_file_, "also write the table to this file");
    app_->add_option("--fault", faults_,
                     "also score the scenarios with this fault (repeatable, all at once): beacon_dies=ID@T, "
                     "tof_outage=FROM:TO, echoes=P; the clean row comes first");
    app_->add_flag("--identified", identified_,
                   "every range carries its beacon's id, also in a scenario whose beacons are anonymous (the "
                   "association given, as the bound assumes: for estimators that need it, such as range_ekf)");
    app_->add_option("--delay-ms", delay_ms_,
                     "also score with every TOF and scan delivered late by a uniform random 0..D ms "
                     "(odometry on time); the in-order row comes first")
        ->transform(real_in(0.0, kMaxDelayMs));
  }
  bool runs_participants() const override { return false; }
  int execute() override {
    load_estimator_plugins(estimator_plugins_);
    std::vector<AccuracyRow> rows;
    std::vector<std::string> failed_runs;
    const bool variants_compared = !faults_.empty() || delay_ms_ > 0.0;
    for (const auto& file : scenarios_) {
      const std::vector<Variant> variants = variants_of(file, variants_compared);
      for (const auto& estimator : estimators_) {
        for (const Variant& variant : variants) {
          rows.push_back(score(variant, estimator, failed_runs));
        }
      }
    }
    // Each table, then the same runs beside the posterior Cramer-Rao bound (docs/bound.md).
    const std::string table = (table_ == "distance" ? distance_table_markdown(rows)
                               : table_ == "path"   ? path_table_markdown(rows)
                                                    : accuracy_table_markdown(rows)) +
                              "\nposterior Cramer-Rao bound along the true path (docs/bound.md):\n\n" +
                              bound_table_markdown(rows);
    // The file first: a reader of stdout that leaves early (`| head`) ends the command (SIGPIPE).
    if (!out_file_.empty()) {
      std::ofstream out(out_file_);
      out << table;
      if (!out.flush()) throw std::runtime_error("writing '" + out_file_ + "' failed");
    }
    std::cout << table;
    if (variants_compared) {
      // What the faults cost: the typed refusals of the decoder and localizer, over all seeds.
      std::cout << "\nrefusals summed over the seeds:\n";
      for (const auto& row : rows) {
        std::cout << "- " << row.scenario << ", " << row.estimator << ":";
        if (row.rejections.empty()) std::cout << " none";
        for (const auto& [reason, n] : row.rejections) std::cout << ' ' << reason << '=' << n;
        std::cout << '\n';
      }
    }
    if (!failed_runs.empty()) {
      std::cerr << "beaconloc accuracy: " << failed_runs.size() << " run(s) gave no scored pose, left out of "
                << "the table:\n";
      for (const auto& f : failed_runs) std::cerr << "- " << f << '\n';
      return 1;
    }
    return 0;
  }

 private:
  struct Variant {
    std::string label;
    sim::Scenario scenario;
    Delivery delivery;
  };
  // The clean, in-order scenario, then (when compared) the same with the faults and the delay.
  std::vector<Variant> variants_of(const std::string& file, bool compared) const {
    sim::Scenario clean = sim::load_scenario_file(file);
    if (odometry_k_v_m_) clean.odometry_k_v_m = *odometry_k_v_m_;
    if (identified_ && !clean.identified) {
      clean.identified = true;
      clean.name += " (identified)";
    }
    std::vector<Variant> variants{{clean.name, clean, {}}};
    if (!compared) return variants;
    Variant v{clean.name, clean, {}};
    for (const auto& fault : faults_) {
      sim::apply_fault(v.scenario, fault);
      v.label += " + " + fault;
    }
    if (delay_ms_ > 0.0) {
      v.delivery.max_measurement_delay_ns = s_to_ns(delay_ms_ * 1e-3);
      std::ostringstream label;
      label << " + delay 0.." << delay_ms_ << " ms";
      v.label += label.str();
    }
    variants.push_back(v);
    return variants;
  }
  // Every seed of one variant and estimator; a run that gave nothing is no 0 m: a failure.
  AccuracyRow score(const Variant& variant, const std::string& estimator, std::vector<std::string>& failed_runs) const {
    AccuracyRow row{variant.label, estimator, {}, {}, {}, {}, {}, false};
    for (int k = 0; k < seeds_; ++k) {
      const std::uint64_t seed = first_seed_ + static_cast<std::uint64_t>(k);
      const OfflineRunResult r =
          run_scenario_offline(variant.scenario, seed, estimator, parameters_, settle_s_, variant.delivery);
      if (r.metrics.samples == 0) {
        failed_runs.push_back(variant.label + ", " + estimator + ", seed " + std::to_string(seed) + ": " +
                              std::to_string(r.poses) + " pose(s), none scored");
        continue;
      }
      row.runs.push_back(r.metrics);
      if (r.bound.rms) row.bounds.push_back(*r.bound.rms);
      if (!r.bound.unavailable.empty()) row.bound_unavailable = r.bound.unavailable;
      row.laser_fused = r.bound.laser_fused;
      if (r.associations.total()) row.associations.push_back(r.associations);
      for (const auto& [reason, n] : r.rejections.rejected_by_reason()) row.rejections[reason] += n;
    }
    return row;
  }

  std::vector<std::string> scenarios_, estimators_{"range_ekf"}, estimator_plugins_, parameters_, faults_;
  int seeds_ = 10;
  std::uint64_t first_seed_ = 1;
  double settle_s_ = 0.0;
  std::optional<double> odometry_k_v_m_;
  std::string table_ = "pose";
  std::string out_file_;
  double delay_ms_ = 0.0;
  bool identified_ = false;
};

}  // namespace

void add_offline_commands(CLI::App& app, std::vector<std::unique_ptr<Command>>& out) {
  out.push_back(std::make_unique<EvalCommand>(app));
  out.push_back(std::make_unique<AccuracyCommand>(app));
}

}  // namespace beaconloc::cli
