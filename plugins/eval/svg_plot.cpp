#include "svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace beaconloc {
namespace {

// Maps a data rectangle onto a pixel rectangle (y up in the data, down in SVG).
struct Frame {
  double x0, y0, x1, y1;            // data bounds
  double left, top, width, height;  // pixels
  double px(double x) const { return left + (x - x0) / (x1 - x0) * width; }
  double py(double y) const { return top + height - (y - y0) / (y1 - y0) * height; }
};

double nice_step(double span) {
  const double raw = span / 6.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10.0 * p;
}

// A tick label with the decimals the step needs, and no "-0".
std::string tick(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(v) < step * 1e-6) v = 0.0;
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(decimals);
  s << v;
  return s.str();
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

void axes(std::ostream& out, const Frame& f, const std::string& x_label, const std::string& y_label) {
  out << "<rect x='" << f.left << "' y='" << f.top << "' width='" << f.width << "' height='" << f.height
      << "' fill='none' stroke='#444'/>\n";
  const double sx = nice_step(f.x1 - f.x0), sy = nice_step(f.y1 - f.y0);
  for (double x = std::ceil(f.x0 / sx) * sx; x <= f.x1 + 1e-9; x += sx) {
    out << "<line x1='" << f.px(x) << "' y1='" << f.top << "' x2='" << f.px(x) << "' y2='" << f.top + f.height
        << "' stroke='#ddd'/><text x='" << f.px(x) << "' y='" << f.top + f.height + 16
        << "' font-size='12' text-anchor='middle'>" << tick(x, sx) << "</text>\n";
  }
  for (double y = std::ceil(f.y0 / sy) * sy; y <= f.y1 + 1e-9; y += sy) {
    out << "<line x1='" << f.left << "' y1='" << f.py(y) << "' x2='" << f.left + f.width << "' y2='"
        << f.py(y) << "' stroke='#ddd'/><text x='" << f.left - 6 << "' y='" << f.py(y) + 4
        << "' font-size='12' text-anchor='end'>" << tick(y, sy) << "</text>\n";
  }
  out << "<text x='" << f.left + f.width / 2 << "' y='" << f.top + f.height + 34
      << "' font-size='13' text-anchor='middle'>" << escape(x_label) << "</text>\n"
      << "<text x='" << f.left - 44 << "' y='" << f.top + f.height / 2
      << "' font-size='13' text-anchor='middle' "
      << "transform='rotate(-90 " << f.left - 44 << ' ' << f.top + f.height / 2 << ")'>" << escape(y_label)
      << "</text>\n";
}

template <class Points>
void polyline(std::ostream& out, const Frame& f, const Points& points, const char* colour, double width) {
  if (points.empty()) return;
  const std::size_t stride = std::max<std::size_t>(1, points.size() / 4000);
  out << "<polyline fill='none' stroke='" << colour << "' stroke-width='" << width << "' points='";
  for (std::size_t i = 0; i < points.size(); i += stride) {
    out << f.px(points[i].x()) << ',' << f.py(points[i].y()) << ' ';
  }
  out << "'/>\n";
}

std::ofstream open_svg(const std::string& path, int width, int height, const std::string& title) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << height
      << "' font-family='sans-serif'>\n<rect width='100%' height='100%' fill='white'/>\n"
      << "<text x='" << width / 2 << "' y='22' font-size='16' text-anchor='middle'>" << escape(title)
      << "</text>\n";
  out.setf(std::ios::fixed);
  out.precision(2);
  return out;
}

void close_svg(std::ofstream& out, const std::string& path) {
  out << "</svg>\n";
  if (!out.flush()) throw std::runtime_error("writing '" + path + "' failed");
}

}  // namespace

void write_trajectory_svg(const std::string& path, const std::string& title, const TruthTrack& truth,
                          const std::vector<EstimateRow>& estimates, const BeaconMap& beacons,
                          const std::optional<OccupancyGrid>& map) {
  std::vector<Eigen::Vector2d> truth_xy, estimate_xy;
  for (const auto& [stamp, s] : truth.samples()) truth_xy.push_back(s.pose_map_base.head<2>());
  for (const auto& r : estimates) estimate_xy.push_back(r.estimate.pose_map_base.head<2>());
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  auto extend = [&](const Eigen::Vector2d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  for (const auto& p : truth_xy) extend(p);
  for (const auto& p : estimate_xy) extend(p);
  for (const auto& b : beacons.beacons()) extend(b.position_map_m.head<2>());
  if (map) {
    extend(map->origin_m());
    extend(map->origin_m() + map->resolution_m() * Eigen::Vector2d(map->width(), map->height()));
  }
  if (!std::isfinite(lo.x())) lo = hi = Eigen::Vector2d::Zero();
  const double margin = std::max(0.5, 0.05 * (hi - lo).maxCoeff());
  lo -= Eigen::Vector2d::Constant(margin);
  hi += Eigen::Vector2d::Constant(margin);
  // Equal scales on both axes.
  const double plot_w = 760.0, plot_h = 560.0;
  const double scale = std::min(plot_w / (hi.x() - lo.x()), plot_h / (hi.y() - lo.y()));
  const Frame f{lo.x(), lo.y(), lo.x() + plot_w / scale, lo.y() + plot_h / scale, 70.0, 40.0, plot_w, plot_h};

  auto out = open_svg(path, 860, 670, title);
  if (map) {  // occupied cells, one rectangle per run of a row
    const double r = map->resolution_m();
    for (int iy = 0; iy < map->height(); ++iy) {
      for (int ix = 0; ix < map->width();) {
        if (!map->occupied(ix, iy)) {
          ++ix;
          continue;
        }
        int end = ix;
        while (end < map->width() && map->occupied(end, iy)) ++end;
        const Eigen::Vector2d a = map->origin_m() + r * Eigen::Vector2d(ix, iy + 1);
        out << "<rect x='" << f.px(a.x()) << "' y='" << f.py(a.y()) << "' width='" << (end - ix) * r * scale
            << "' height='" << r * scale << "' fill='#bbb'/>\n";
        ix = end;
      }
    }
  }
  axes(out, f, "x (m)", "y (m)");
  polyline(out, f, truth_xy, "#111", 2.0);
  polyline(out, f, estimate_xy, "#1f77d4", 1.3);
  for (const auto& b : beacons.beacons()) {
    const double x = f.px(b.position_map_m.x()), y = f.py(b.position_map_m.y());
    out << "<polygon points='" << x << ',' << y - 7 << ' ' << x - 6 << ',' << y + 5 << ' ' << x + 6 << ','
        << y + 5 << "' fill='#d62728'/><text x='" << x + 8 << "' y='" << y - 6
        << "' font-size='11' fill='#d62728'>" << b.id << "</text>\n";
  }
  out << "<g font-size='12'><line x1='600' y1='652' x2='625' y2='652' stroke='#111' stroke-width='2'/>"
      << "<text x='630' y='656'>truth</text><line x1='680' y1='652' x2='705' y2='652' stroke='#1f77d4' "
      << "stroke-width='2'/><text x='710' y='656'>estimate</text><polygon points='772,645 766,657 778,657' "
      << "fill='#d62728'/><text x='784' y='656'>beacon</text></g>\n";
  close_svg(out, path);
}

void write_error_svg(const std::string& path, const std::string& title,
                     const std::vector<ErrorPoint>& errors) {
  auto out = open_svg(path, 860, 620, title);
  double t_max = 1.0, p_max = 0.01, h_max = 0.1;
  bool any_heading = false;
  for (const auto& e : errors) {
    t_max = std::max(t_max, e.t_s);
    p_max = std::max(p_max, e.position_m);
    if (e.heading_deg) {
      any_heading = true;
      h_max = std::max(h_max, std::abs(*e.heading_deg));
    }
  }
  const Frame fp{0.0, 0.0, t_max, p_max * 1.05, 80.0, 40.0, 740.0, 220.0};
  axes(out, fp, "time (s)", "position error (m)");
  std::vector<Eigen::Vector2d> ep, eh;
  for (const auto& e : errors) {
    ep.emplace_back(e.t_s, e.position_m);
    if (e.heading_deg) eh.emplace_back(e.t_s, *e.heading_deg);
  }
  polyline(out, fp, ep, "#1f77d4", 1.2);
  if (any_heading) {
    const Frame fh{0.0, -h_max * 1.05, t_max, h_max * 1.05, 80.0, 330.0, 740.0, 220.0};
    axes(out, fh, "time (s)", "heading error (deg)");
    polyline(out, fh, eh, "#2ca02c", 1.2);
  } else {
    out << "<text x='450' y='440' font-size='14' text-anchor='middle'>no heading in the ground "
           "truth</text>\n";
  }
  close_svg(out, path);
}

void write_cdf_svg(const std::string& path, const std::string& title, const std::string& x_label,
                   const std::vector<CdfSeries>& series) {
  static const char* const kColours[] = {"#1f77d4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"};
  auto out = open_svg(path, 860, 520, title);
  double x_max = 1e-3;
  for (const CdfSeries& s : series) {
    for (double v : s.values) {
      if (std::isfinite(v)) x_max = std::max(x_max, v);
    }
  }
  const Frame f{0.0, 0.0, x_max * 1.05, 1.0, 80.0, 40.0, 740.0, 400.0};
  axes(out, f, x_label, "fraction of values at most x");
  std::size_t k = 0;
  for (const CdfSeries& s : series) {
    std::vector<double> sorted;
    for (double v : s.values) {
      if (std::isfinite(v)) sorted.push_back(v);
    }
    std::sort(sorted.begin(), sorted.end());
    // A step at every value up to kMaxSteps values; beyond, at kMaxSteps evenly spaced ranks (the
    // plot keeps its shape and stays small: 2 800 beacons x 4 series made 230 kB).
    constexpr std::size_t kMaxSteps = 400;
    std::vector<Eigen::Vector2d> steps;
    steps.emplace_back(0.0, 0.0);
    const std::size_t n = sorted.size();
    const std::size_t shown = std::min(n, kMaxSteps);
    for (std::size_t step = 0; step < shown; ++step) {
      const std::size_t i = shown == n ? step : (step * (n - 1)) / (shown - 1);
      steps.emplace_back(sorted[i], static_cast<double>(i) / static_cast<double>(n));
      steps.emplace_back(sorted[i], static_cast<double>(i + 1) / static_cast<double>(n));
    }
    const char* colour = kColours[k % (sizeof kColours / sizeof kColours[0])];
    polyline(out, f, steps, colour, 1.4);
    out << "<text x='" << 600 << "' y='" << 300 + 18 * static_cast<int>(k) << "' font-size='13' fill='" << colour
        << "'>" << escape(s.label) << "</text>\n";
    ++k;
  }
  close_svg(out, path);
}

}  // namespace beaconloc
