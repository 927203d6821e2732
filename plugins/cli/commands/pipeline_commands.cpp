// The commands that run the whole pipeline on a source: demo (the built-in scenario in real time)
// and run (a scenario or a recording as fast as it goes, scored and written out).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>

#include "command.hpp"
#include "options.hpp"
#include "pipeline.hpp"

namespace beaconloc::cli {
namespace {

// What demo and run share: DDS, the gateway, the localizer, --out and --bridge.
class PipelineCommand : public Command {
 protected:
  using Command::Command;
  void add_common_options() {
    dds_option_set(dds_).add_to(app_);
    gateway_option_set(gateway_, seed_).add_to(app_);
    localizer_option_set(localizer_, false).add_to(app_);
  }
  bool given(const char* option) const { return app_->count(option) > 0; }
  // Runs it, prints the participants' counts and the score; exit 1 when no pose came, or none at
  // a stamp the ground truth covers (where the source has truth).
  int run_and_score(PipelineOptions o, LoadedSource source, const char* name) const {
    if (!o.dds.security.enclave.empty()) {
      throw std::invalid_argument(std::string("--enclave names one participant's identity: ") + name +
                                  " starts several, each with its role's (dds::default_enclave)");
    }
    std::cout << "beaconloc " << name << ": " << source.label << ", estimator " << o.localizer.estimator << ", seed "
              << source.seed << '\n';
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
    const PipelineResult r = run_pipeline(o, std::move(source), self.string());
    std::cout << r.diagnostics;
    // A source without ground truth (a replay without gt.csv) gives poses that are not scored.
    const bool has_truth = r.truth_samples > 0;
    std::printf("poses: %zu at %.1f Hz; %s\n", r.poses, r.pose_rate_hz,
                has_truth ? format_metrics(r.metrics).c_str() : "no ground truth: not scored");
    if (!r.newest_state.empty()) std::cout << "estimator state at the end (robot name value +- sigma): " << r.newest_state << '\n';
    if (r.bound && r.metrics.samples) {
      std::cout << format_pose_bound(*r.bound, r.metrics) << '\n';
    }
    if (!o.out_dir.empty()) {
      std::cout << "wrote " << o.out_dir << "/{truth,estimate,beacons}.csv, metrics.json, trajectory.svg, error.svg"
                << (r.estimator_state_rows ? ", estimator_state.csv" : "") << '\n';
    }
    if (r.poses == 0) {
      std::cerr << "beaconloc: no pose was estimated (the localizer's last status is above)\n";
      return 1;
    }
    if (has_truth && r.metrics.samples == 0) {
      std::cerr << "beaconloc: no pose was at a stamp the ground truth covers"
                << (r.metrics.samples_before_scoring ? " from the scenario's score_from_s" : "") << '\n';
      return 1;
    }
    return 0;
  }

  dds::DdsOptions dds_;
  GatewayOptions gateway_;
  std::optional<std::uint64_t> seed_;
  LocalizerSettings localizer_;
  std::string out_dir_;
  bool with_bridge_ = false;
};

class DemoCommand : public PipelineCommand {
 public:
  explicit DemoCommand(CLI::App& app)
      : PipelineCommand(
            app.add_subcommand("demo", "the whole pipeline in one process on the built-in scenario, in real time")) {
    app_->add_flag("--bridge", with_bridge_, "also run the ROS 2 bridge in this process (ROS 2 tools see the demo)");
    add_common_options();
    app_->add_option("--out", out_dir_, "write truth, estimates, metrics and plots into this directory");
  }
  int execute() override {
    PipelineOptions o;
    o.dds = dds_;
    o.localizer = localizer_;
    o.out_dir = out_dir_;
    if (with_bridge_) o.bridge = bridge::BridgeOptions{};
    LoadedSource source = load_source(SourceChoice{}, seed_);
    o.gateway = gateway_;
    o.gateway.seed = source.seed;
    if (!given("--duration-s")) o.gateway.duration_s = 20.0;
    o.print_poses = true;
    if (!out_dir_.empty() && o.gateway.truth_csv.empty()) o.gateway.truth_csv = out_dir_ + "/truth.csv";
    return run_and_score(std::move(o), std::move(source), "demo");
  }
};

class RunCommand : public PipelineCommand {
 public:
  explicit RunCommand(CLI::App& app)
      : PipelineCommand(app.add_subcommand(
            "run",
            "gateway, decoder and localizer over DDS on a scenario or a recording, as fast as they go; "
            "writes truth.csv, estimate.csv, metrics.json and plots")) {
    dds_option_set(dds_).add_to(app_);
    const std::vector<CLI::Option*> source = source_option_set(source_).add_to(app_);
    source[0]->excludes(source[1]);  // --scenario or --replay
    gateway_option_set(gateway_, seed_).add_to(app_);
    decoder_option_set(decoder_, max_age_ms_).add_to(app_);
    localizer_option_set(localizer_, false).add_to(app_);
    app_->add_option("--out", out_dir_, "output directory")->required();
    app_->add_flag("--processes", processes_, "one process per participant (needs --speed)");
    app_->add_flag("--bridge", with_bridge_, "also run the ROS 2 bridge (in the run's process)");
  }
  int execute() override {
    if (with_bridge_ && processes_) {
      throw std::invalid_argument("--bridge runs in the run's process; with --processes start `beaconloc bridge`");
    }
    PipelineOptions o;
    o.dds = dds_;
    o.decoder = decoder_config_with_age(decoder_, max_age_ms_);
    o.localizer = localizer_;
    o.out_dir = out_dir_;
    o.processes = processes_;
    if (with_bridge_) o.bridge = bridge::BridgeOptions{};
    LoadedSource source = load_source(source_, seed_);
    o.gateway = gateway_;
    o.gateway.seed = source.seed;
    if (!given("--speed")) o.gateway.speed = processes_ ? 10.0 : 0.0;  // 0: as fast as it goes
    if (!given("--duration-s") && source.scenario) o.gateway.duration_s = source.scenario->duration_s;
    // A scenario states its beacon system's range limits and noise; the decoder takes them
    // unless told otherwise (its defaults are seed 000's: seed 001's ranges reach 14 m).
    if (source.scenario) {
      if (!given("--min-range-m")) o.decoder.min_range_m = source.scenario->min_range_m;
      if (!given("--max-range-m")) o.decoder.max_range_m = source.scenario->max_range_m;
      if (!given("--range-sigma-m")) o.decoder.range_sigma_m = source.scenario->range_sigma_m;
    }
    o.print_progress = true;
    if (!out_dir_.empty() && o.gateway.truth_csv.empty() && !processes_) o.gateway.truth_csv = out_dir_ + "/truth.csv";
    o.gateway.wall_clock_stamps = false;  // the same seed gives byte-identical files
    if (!processes_) o.gateway.record_dir = out_dir_;
    return run_and_score(std::move(o), std::move(source), "run");
  }

 private:
  SourceChoice source_;
  TofDecoderConfig decoder_;
  double max_age_ms_ = max_age_ms_of(decoder_);
  bool processes_ = false;
};

}  // namespace

void add_pipeline_commands(CLI::App& app, std::vector<std::unique_ptr<Command>>& out) {
  out.push_back(std::make_unique<DemoCommand>(app));
  out.push_back(std::make_unique<RunCommand>(app));
}

}  // namespace beaconloc::cli
