// The figures of a run (percentiles of the samples, ratios to 3 raw hops, match fractions), their
// medians over runs, and their table and CSV rows.
#include "figures.hpp"

#include <algorithm>
#include <cstdio>

#include "bench_support.hpp"

namespace beaconloc::latency {

Stats stats_of(const std::vector<double>& v) {
  Stats s;
  s.n = v.size();
  if (v.empty()) return s;
  s.p50 = bench::percentile(v, 0.50);
  s.p99 = bench::percentile(v, 0.99);
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

Figures figures_of(const PipelineResult& pipeline, const HopResult& hop) {
  Figures f;
  f.pipeline = stats_of(pipeline.latency_us);
  f.hop = stats_of(hop.hop_us);
  f.ratio50 = f.pipeline.p50 / (f.hop.p50 * kPipelineHops);
  f.ratio99 = f.pipeline.p99 / (f.hop.p99 * kPipelineHops);
  f.b2b = stats_of(hop.b2b_hop_us);
  f.b2b_ratio50 = f.pipeline.p50 / (f.b2b.p50 * kPipelineHops);
  f.b2b_ratio99 = f.pipeline.p99 / (f.b2b.p99 * kPipelineHops);
  f.timed = pipeline.timed;
  f.matched = f.timed ? static_cast<double>(f.pipeline.n) / static_cast<double>(f.timed) : 0.0;
  f.corrections = f.pipeline.n
                      ? static_cast<double>(pipeline.correction_matches) / static_cast<double>(f.pipeline.n)
                      : 0.0;
  f.tofs = pipeline.tofs_written;
  f.poses = pipeline.poses;
  f.pose_rate_hz = pipeline.pose_rate_hz;
  f.pings = hop.sent;
  f.lost = hop.lost;
  if (pipeline.window_samples && pipeline.window_s > 0.0) {
    f.pipeline_cpu_us_per_sample = pipeline.children_cpu_s * 1e6 / static_cast<double>(pipeline.window_samples);
    f.pipeline_cpu_percent = 100.0 * pipeline.children_cpu_s / pipeline.window_s;
  }
  if (hop.sent) f.echo_cpu_us_per_round_trip = hop.echo_cpu_s * 1e6 / static_cast<double>(hop.sent);
  return f;
}

Figures median_of(const std::vector<Figures>& runs) {
  auto m = [&](auto get) {
    std::vector<double> v;
    for (const auto& f : runs) v.push_back(static_cast<double>(get(f)));
    return bench::median(v);
  };
  auto stats = [&](auto member) {
    Stats s;
    s.n = static_cast<std::size_t>(m([&](const Figures& x) { return (x.*member).n; }));
    s.p50 = m([&](const Figures& x) { return (x.*member).p50; });
    s.p99 = m([&](const Figures& x) { return (x.*member).p99; });
    s.max = m([&](const Figures& x) { return (x.*member).max; });
    return s;
  };
  Figures f;
  f.pipeline = stats(&Figures::pipeline);
  f.hop = stats(&Figures::hop);
  f.b2b = stats(&Figures::b2b);
  f.b2b_ratio50 = m([](const Figures& x) { return x.b2b_ratio50; });
  f.b2b_ratio99 = m([](const Figures& x) { return x.b2b_ratio99; });
  f.ratio50 = m([](const Figures& x) { return x.ratio50; });
  f.ratio99 = m([](const Figures& x) { return x.ratio99; });
  f.matched = m([](const Figures& x) { return x.matched; });
  f.corrections = m([](const Figures& x) { return x.corrections; });
  f.timed = static_cast<std::size_t>(m([](const Figures& x) { return x.timed; }));
  f.tofs = static_cast<std::size_t>(m([](const Figures& x) { return x.tofs; }));
  f.poses = static_cast<std::size_t>(m([](const Figures& x) { return x.poses; }));
  f.pose_rate_hz = m([](const Figures& x) { return x.pose_rate_hz; });
  f.pings = static_cast<std::size_t>(m([](const Figures& x) { return x.pings; }));
  f.lost = static_cast<std::size_t>(m([](const Figures& x) { return x.lost; }));
  f.pipeline_cpu_us_per_sample = m([](const Figures& x) { return x.pipeline_cpu_us_per_sample; });
  f.pipeline_cpu_percent = m([](const Figures& x) { return x.pipeline_cpu_percent; });
  f.echo_cpu_us_per_round_trip = m([](const Figures& x) { return x.echo_cpu_us_per_round_trip; });
  return f;
}

void print_header(const std::string& title) {
  std::printf("\n%s\n%-9s %-42s %6s %10s %10s %10s\n", title.c_str(), "transport", "path", "n", "p50 us",
              "p99 us", "max us");
}

void print_figures(const std::string& transport, const Figures& f) {
  const char* t = transport.c_str();
  std::printf("%-9s %-42s %6zu %10.1f %10.1f %10.1f\n", t, "pipeline: RawTof write -> pose (3 hops)",
              f.pipeline.n, f.pipeline.p50, f.pipeline.p99, f.pipeline.max);
  std::printf("%-9s %-42s %6zu %10.1f %10.1f %10.1f\n", t, "raw hop: RawTof ping-pong round trip / 2",
              f.hop.n, f.hop.p50, f.hop.p99, f.hop.max);
  std::printf("%-9s %-42s %6s %10.2f %10.2f\n", t, "ratio: pipeline / (3 x raw hop)", "", f.ratio50,
              f.ratio99);
  if (f.b2b.n) {
    std::printf("%-9s %-42s %6zu %10.1f %10.1f %10.1f\n", t, "(reference) raw hop, back-to-back pings",
                f.b2b.n, f.b2b.p50, f.b2b.p99, f.b2b.max);
    std::printf("%-9s %-42s %6s %10.2f %10.2f\n", t, "(reference) pipeline / (3 x back-to-back)", "",
                f.b2b_ratio50, f.b2b_ratio99);
  }
  std::printf(
      "%-9s matched %.1f %% of %zu timed TOFs (the first of each slot), %.1f %% of the matches by a "
      "correction pose; %zu TOFs and %zu poses (%.1f Hz) in all; %zu of %zu pings unanswered\n",
      t, 100.0 * f.matched, f.timed, 100.0 * f.corrections, f.tofs, f.poses, f.pose_rate_hz, f.lost, f.pings);
  std::printf(
      "%-9s CPU: decoder + localizer %.1f us per sample written to them (%.2f %% of a core); echo %.1f us per "
      "round trip (clock ticks of 10 ms: coarse over short runs)\n",
      t, f.pipeline_cpu_us_per_sample, f.pipeline_cpu_percent, f.echo_cpu_us_per_round_trip);
  std::fflush(stdout);
}

void append_csv(const std::string& path, const std::string& benchmark, const std::string& transport,
                const Figures& f) {
  bench::Results r(benchmark, transport);
  r.add("pipeline_p50", f.pipeline.p50, "us");
  r.add("pipeline_p99", f.pipeline.p99, "us");
  r.add("pipeline_max", f.pipeline.max, "us");
  r.add("pipeline_samples", static_cast<double>(f.pipeline.n), "count");
  r.add("hop_p50", f.hop.p50, "us");
  r.add("hop_p99", f.hop.p99, "us");
  r.add("hop_max", f.hop.max, "us");
  r.add("hop_samples", static_cast<double>(f.hop.n), "count");
  r.add("hops", kPipelineHops, "count");
  r.add("ratio_p50", f.ratio50, "ratio");
  r.add("ratio_p99", f.ratio99, "ratio");
  r.add("matched_fraction", f.matched, "fraction");
  r.add("correction_pose_fraction", f.corrections, "fraction");
  r.add("pipeline_cpu_per_sample", f.pipeline_cpu_us_per_sample, "us");
  r.add("pipeline_cpu", f.pipeline_cpu_percent, "percent_of_core");
  r.add("echo_cpu_per_round_trip", f.echo_cpu_us_per_round_trip, "us");
  if (f.b2b.n) {
    r.add("hop_b2b_p50", f.b2b.p50, "us");
    r.add("hop_b2b_p99", f.b2b.p99, "us");
    r.add("hop_b2b_max", f.b2b.max, "us");
    r.add("hop_b2b_samples", static_cast<double>(f.b2b.n), "count");
    r.add("ratio_b2b_p50", f.b2b_ratio50, "ratio");
    r.add("ratio_b2b_p99", f.b2b_ratio99, "ratio");
  }
  r.append_csv(path);
}

}  // namespace beaconloc::latency
