// A site's beacon calibration (core/beacon_calibration.hpp) and its file
// (core/calibration_store.hpp): checked whole, read back bit for bit, every damaged file refused
// by reason, and a writer killed while it writes leaves the previous calibration or the new one.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <limits>
#include <random>
#include <sstream>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/calibration_store.hpp"

namespace beaconloc {
namespace {

BeaconCalibration calibration(std::uint32_t first_group, std::size_t groups, std::size_t beacons_per_group,
                              double shift_m) {
  BeaconCalibration c;
  std::uint32_t id = 1;
  for (std::size_t g = 0; g < groups; ++g) {
    GroupCalibration group;
    group.group = first_group + static_cast<std::uint32_t>(g);
    group.stamp_ns = 123'456'789'012 + static_cast<StampNs>(g);
    const double yaw = 0.1 * static_cast<double>(g) + 1.0 / 3.0;
    group.transform << std::cos(yaw), std::sin(yaw), 12.0 + shift_m + static_cast<double>(g), -2.0 / 7.0;
    group.mean_error_m = 0.0123456789;
    for (std::size_t b = 0; b < beacons_per_group; ++b) {
      CalibratedBeacon beacon;
      beacon.id = id++;
      beacon.position_map_m << 10.0 * static_cast<double>(g) + 0.1 * static_cast<double>(b) + shift_m, M_PI, 3.5;
      beacon.covariance_m2 << 0.01, 0.002, 0.002, 0.02;
      group.beacons.push_back(beacon);
    }
    c.groups.push_back(group);
  }
  return c;
}

// The temporaries save_calibration made for path and did not rename (a killed writer's).
std::vector<std::string> temporaries_of(const std::string& path) {
  std::vector<std::string> out;
  const std::filesystem::path p(path);
  const std::string prefix = p.filename().string() + ".tmp.";
  for (const auto& entry : std::filesystem::directory_iterator(p.parent_path())) {
    if (entry.path().filename().string().rfind(prefix, 0) == 0) out.push_back(entry.path().string());
  }
  return out;
}

std::string temporary_path(const std::string& name) {
  return ::testing::TempDir() + "beaconloc_" + std::to_string(::getpid()) + "_" + name;
}

TEST(BeaconCalibration, EveryProblemIsFoundAndNamed) {
  EXPECT_TRUE(check_calibration(calibration(3, 2, 4, 0.0)).ok());
  EXPECT_TRUE(check_calibration(BeaconCalibration{}).ok());  // nothing calibrated yet
  const auto problem_after = [](auto change) {
    BeaconCalibration c = calibration(3, 2, 4, 0.0);
    change(c);
    return check_calibration(c).problem;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(problem_after([&](BeaconCalibration& c) { c.groups[1].beacons[2].position_map_m.x() = nan; }),
            CalibrationProblem::kNonFinite);
  EXPECT_EQ(problem_after([&](BeaconCalibration& c) { c.groups[0].transform(1) = nan; }), CalibrationProblem::kNonFinite);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[0].beacons[0].position_map_m.y() = 2e6; }),
            CalibrationProblem::kOutOfRange);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[0].stamp_ns = -1; }), CalibrationProblem::kOutOfRange);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[0].mean_error_m = -0.1; }), CalibrationProblem::kOutOfRange);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[0].transform.head<2>() *= 3.0; }),
            CalibrationProblem::kDegenerateTransform);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[0].transform.head<2>().setZero(); }),
            CalibrationProblem::kDegenerateTransform);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[1].group = 0; }), CalibrationProblem::kGroupZero);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[1].group = c.groups[0].group; }), CalibrationProblem::kDuplicateGroup);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[1].beacons[0].id = c.groups[0].beacons[3].id; }),
            CalibrationProblem::kDuplicateBeacon);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[1].beacons[1].id = 0xFFFFFFFFu; }),
            CalibrationProblem::kReservedId);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[1].beacons.clear(); }), CalibrationProblem::kEmptyGroup);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[0].beacons[1].covariance_m2(0, 1) = 0.5; }),
            CalibrationProblem::kBadCovariance);  // not symmetric
  EXPECT_EQ(problem_after([](BeaconCalibration& c) { c.groups[0].beacons[1].covariance_m2(1, 1) = -1e-6; }),
            CalibrationProblem::kBadCovariance);
  EXPECT_EQ(problem_after([](BeaconCalibration& c) {
              c.groups[0].beacons[1].covariance_m2(0, 1) = c.groups[0].beacons[1].covariance_m2(1, 0) = 0.1;
            }),
            CalibrationProblem::kBadCovariance);  // not positive semi-definite
  const CalibrationCheck named = check_calibration(calibration(3, 2, 4, 0.0));
  EXPECT_EQ(named.describe(), "group 0: none");
}

TEST(CalibrationStore, ACalibrationIsReadBackBitForBit) {
  const BeaconCalibration c = calibration(3, 7, 4, 0.0);
  CalibrationFileResult r;
  const auto parsed = parse_calibration(format_calibration(c), &r);
  ASSERT_TRUE(parsed) << to_string(r.problem) << " " << r.detail;
  EXPECT_TRUE(*parsed == c);
  const std::string path = temporary_path("round_trip.calibration");
  ASSERT_TRUE(save_calibration(path, c).ok());
  const auto loaded = load_calibration(path, &r);
  ASSERT_TRUE(loaded) << to_string(r.problem) << " " << r.detail;
  EXPECT_TRUE(*loaded == c);
  // Saving again replaces it whole.
  const BeaconCalibration d = calibration(3, 2, 4, 0.5);
  ASSERT_TRUE(save_calibration(path, d).ok());
  EXPECT_TRUE(*load_calibration(path, &r) == d);
  // An invalid calibration is never written: the file keeps the last good one.
  BeaconCalibration bad = d;
  bad.groups[0].beacons[0].position_map_m.x() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(save_calibration(path, bad).problem, CalibrationFileProblem::kInvalid);
  EXPECT_TRUE(*load_calibration(path, &r) == d);
  std::remove(path.c_str());
}

TEST(CalibrationStore, EveryDamagedFileIsRefusedByReason) {
  CalibrationFileResult r;
  EXPECT_FALSE(load_calibration(temporary_path("never_written"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMissing);
  EXPECT_FALSE(load_calibration(::testing::TempDir(), &r));  // a directory
  EXPECT_NE(r.problem, CalibrationFileProblem::kNone);
  EXPECT_NE(r.problem, CalibrationFileProblem::kMissing);
  const std::string text = format_calibration(calibration(3, 2, 4, 0.0));
  // Torn at every length: refused, never a part of it taken.
  for (std::size_t n = 0; n < text.size(); ++n) {
    EXPECT_FALSE(parse_calibration(text.substr(0, n), &r)) << n;
    EXPECT_TRUE(r.problem == CalibrationFileProblem::kMalformed ||
                r.problem == CalibrationFileProblem::kChecksumMismatch)
        << n << " " << to_string(r.problem);
  }
  // One character changed anywhere before the checksum line: the checksum says so.
  const std::size_t checksum_at = text.rfind("checksum");
  for (std::size_t i = 0; i < checksum_at; i += 7) {
    std::string edited = text;
    edited[i] = edited[i] == '1' ? '2' : '1';
    EXPECT_FALSE(parse_calibration(edited, &r)) << i;
  }
  // Well formed with a right checksum, and still wrong: the format's and the check's reasons.
  const auto sealed = [](const std::string& body) {
    // The file format_calibration would write for this body (its checksum recomputed).
    const std::string probe = format_calibration(BeaconCalibration{});
    const std::string header = probe.substr(0, probe.find('\n') + 1);
    std::uint64_t h = 1469598103934665603ULL;
    const std::string all = header + body;
    for (const char c : all) {
      h ^= static_cast<unsigned char>(c);
      h *= 1099511628211ULL;
    }
    char line[40];
    std::snprintf(line, sizeof line, "checksum %016llx\n", static_cast<unsigned long long>(h));
    return all + line;
  };
  EXPECT_TRUE(parse_calibration(sealed(""), &r));  // nothing calibrated
  EXPECT_TRUE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 1\nbeacon 41 1 2 3.5 0.01 0 0.01\n"), &r))
      << r.detail;
  EXPECT_FALSE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 1\nbeacon 41 nan 2 3.5 0.01 0 0.01\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMalformed);
  EXPECT_FALSE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 1\nbeacon 41 0x1 2 3.5 0.01 0 0.01\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMalformed);
  EXPECT_FALSE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 1\nbeacon 41  2 3.5 0.01 0 0.01\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMalformed);
  EXPECT_FALSE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 2\nbeacon 41 1 2 3.5 0.01 0 0.01\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMalformed);  // a beacon short
  EXPECT_FALSE(parse_calibration(sealed("beacon 41 1 2 3.5 0.01 0 0.01\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMalformed);  // outside a group
  EXPECT_FALSE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 1\nbeacon 41 1 2 3.5 0.01 0 0.01\nextra\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMalformed);
  EXPECT_FALSE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 1\nbeacon 41 1 2 3.5 -0.01 0 0.01\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kInvalid);
  EXPECT_EQ(r.detail, "group 4: bad_covariance");
  EXPECT_FALSE(parse_calibration(sealed("group 4 10 1 0 2 3 0.1 99999999999\n"), &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kMalformed);  // an absurd count, refused before any allocation
  std::string huge(kMaxCalibrationFileBytes + 1, 'x');
  EXPECT_FALSE(parse_calibration(huge, &r));
  EXPECT_EQ(r.problem, CalibrationFileProblem::kTooLarge);
}

// What several sources found, gathered: a group's surer calibration replaces the one held (then
// the later one, then by value); the groups sorted, so that the same knowledge compares equal
// whatever order it came in.
TEST(BeaconCalibration, MergedGroupByGroupTheSurerReplacingTheOther) {
  BeaconCalibration site;
  const BeaconCalibration first = calibration(5, 2, 3, 0.0);   // groups 5, 6
  BeaconCalibration later = calibration(4, 2, 3, 1.0);         // groups 4, 5: 5 found again, later, as sure
  EXPECT_TRUE(merge_calibration(site, first));
  EXPECT_EQ(site, first);
  EXPECT_FALSE(merge_calibration(site, first));  // nothing new
  EXPECT_TRUE(merge_calibration(site, later));
  ASSERT_EQ(site.groups.size(), 3u);
  EXPECT_EQ(site.groups[0].group, 4u);
  EXPECT_EQ(site.groups[1].group, 5u);
  EXPECT_EQ(site.groups[2].group, 6u);
  EXPECT_EQ(site.groups[1].transform, later.groups[1].transform);  // as sure, and later
  EXPECT_EQ(site.groups[2].transform, first.groups[1].transform);
  // Group 5 earlier but surer: it wins; a later, looser one does not.
  GroupCalibration surer = first.groups[0];
  surer.stamp_ns -= 1000;
  for (auto& b : surer.beacons) b.covariance_m2 *= 0.5;
  EXPECT_TRUE(merge_calibration(site, BeaconCalibration{{surer}}));
  EXPECT_EQ(BeaconCalibration{{site.groups[1]}}, BeaconCalibration{{surer}});
  EXPECT_FALSE(merge_calibration(site, later));
  // Whatever order the versions come in, the same result.
  const std::vector<BeaconCalibration> versions{first, later, BeaconCalibration{{surer}}};
  for (const auto& order : std::vector<std::vector<int>>{{0, 1, 2}, {2, 1, 0}, {1, 2, 0}, {2, 0, 1}}) {
    BeaconCalibration other;
    for (int k : order) merge_calibration(other, versions[static_cast<std::size_t>(k)]);
    EXPECT_EQ(other, site);
  }
}

// Only the groups the map holds as locally referenced, with exactly its beacons, each where the
// group's transform puts the map's beacon (eq. 41-43), are used.
TEST(BeaconCalibration, OnlyTheGroupsThatFitTheMapAreUsed) {
  BeaconList beacons;
  beacons.map_frame.push_back({1, Eigen::Vector3d(0.0, 0.0, 3.0), 1});  // group 1: globally referenced
  beacons.map_frame.push_back({2, Eigen::Vector3d(1.0, 0.0, 3.0), 1});
  beacons.map_frame.push_back({3, Eigen::Vector3d(0.0, 1.0, 3.0), 1});
  for (std::uint32_t id = 10; id < 13; ++id) beacons.group_frame.push_back({id, 2, Eigen::Vector3d(id, 0.5, 3.0)});
  for (std::uint32_t id = 20; id < 23; ++id) beacons.group_frame.push_back({id, 3, Eigen::Vector3d(id, -0.5, 3.0)});
  const BeaconMap map(beacons);
  // Each group of the calibration placed by its transform from the map's group frame.
  const auto placed = [&](std::uint32_t group, std::vector<std::uint32_t> ids) {
    GroupCalibration g;
    g.group = group;
    g.transform << 0.6, 0.8, 10.0, -3.0;
    for (std::uint32_t id : ids) {
      CalibratedBeacon b;
      b.id = id;
      const LocalBeacon* local = map.find_local(id);
      const Eigen::Vector3d p = local ? local->position_group_m : Eigen::Vector3d(1.0, 2.0, 3.0);
      b.position_map_m << 0.6 * p.x() - 0.8 * p.y() + 10.0, 0.8 * p.x() + 0.6 * p.y() - 3.0, p.z();
      g.beacons.push_back(b);
    }
    return g;
  };
  BeaconCalibration c;
  c.groups.push_back(placed(1, {1, 2, 3}));     // a GRULPS
  c.groups.push_back(placed(2, {10, 11}));      // short of the map's beacon 12
  c.groups.push_back(placed(3, {20, 21, 22}));  // fits
  c.groups.push_back(placed(4, {30, 31, 32}));  // no such group
  GroupCalibration moved = placed(2, {10, 11, 12});
  moved.group = 2;
  moved.beacons[2].position_map_m.y() += 0.002;  // 2 mm off its transform: the frame re-surveyed
  c.groups.push_back(moved);
  std::vector<std::uint32_t> unfit;
  const BeaconCalibration fitting = calibration_fitting(c, map, &unfit);
  ASSERT_EQ(fitting.groups.size(), 1u);
  EXPECT_EQ(fitting.groups[0].group, 3u);
  EXPECT_EQ(unfit, (std::vector<std::uint32_t>{1, 2, 4, 2}));
  EXPECT_EQ(calibration_fitting(BeaconCalibration{{placed(2, {10, 11, 12})}}, map).groups.size(), 1u);
}

// A child saves two calibrations in turn as fast as it can; it is killed (SIGKILL: no handler, no
// flush) at a random instant, at least 60 times and until 5 kills have landed inside a save
// (between the temporary's open and its rename; fewer land there on a loaded machine, where a
// forked child takes longer to start saving). Each time the file holds one of the two, whole.
TEST(CalibrationStore, AWriterKilledWhileItWritesLeavesTheOldCalibrationOrTheNew) {
  const std::string path = temporary_path("killed.calibration");
  const BeaconCalibration a = calibration(3, 10, 20, 0.0);  // 200 beacons: ~15 kB a write
  const BeaconCalibration b = calibration(3, 10, 20, 1.0);
  ASSERT_TRUE(save_calibration(path, a).ok());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> fraction(0.0, 2.0);
  int saw_a = 0, saw_b = 0;
  int inside_save = 0;       // kills between the temporary's open and its rename
  int torn_temporaries = 0;  // of those, while the temporary was half written
  constexpr int kMinRounds = 60, kMaxRounds = 600, kInsideSaveWanted = 5;
  int rounds = 0;
  long save_us = 0;  // one save of the child's, as the parent saw it (the newest round's)
  for (int round = 0; round < kMaxRounds && (round < kMinRounds || inside_save < kInsideSaveWanted); ++round) {
    ++rounds;
    // The child says each save it finished. After its first two (however slow a forked,
    // instrumented or loaded child starts), the kill lands within the next two saves' time: the
    // child is saving all along.
    int saved[2];
    ASSERT_EQ(::pipe(saved), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(saved[0]);
      for (int i = 0;; ++i) {
        if (!save_calibration(path, i % 2 == 0 ? b : a).ok()) ::_exit(3);
        const char done = 1;
        if (i < 2 && ::write(saved[1], &done, 1) != 1) ::_exit(4);
      }
    }
    ::close(saved[1]);
    char done = 0;
    ASSERT_EQ(::read(saved[0], &done, 1), 1);
    const auto first = std::chrono::steady_clock::now();
    ASSERT_EQ(::read(saved[0], &done, 1), 1);
    save_us = std::max<long>(
        1, static_cast<long>(
               std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - first).count()));
    ::close(saved[0]);
    ::usleep(static_cast<useconds_t>(fraction(rng) * static_cast<double>(save_us)));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the writer failed on its own: exit " << WEXITSTATUS(status);
    CalibrationFileResult r;
    for (const std::string& temporary : temporaries_of(path)) {  // a killed writer's, left behind
      ++inside_save;
      if (!load_calibration(temporary, &r)) ++torn_temporaries;
      std::remove(temporary.c_str());
    }
    const auto kept = load_calibration(path, &r);
    ASSERT_TRUE(kept) << "round " << round << ": " << to_string(r.problem) << " " << r.detail;
    if (*kept == a) {
      ++saw_a;
    } else if (*kept == b) {
      ++saw_b;
    } else {
      FAIL() << "round " << round << ": a calibration that was never written";
    }
  }
  std::printf("one save of the child %ld us; killed %d writers: the file held the first calibration %d times, the second %d times; %d killed "
              "between the temporary's open and its rename, %d of them with the temporary half written\n",
              static_cast<long>(save_us), rounds, saw_a, saw_b, inside_save, torn_temporaries);
  EXPECT_GE(inside_save, kInsideSaveWanted);
  // The test can tell: a writer that overwrites the file in place, killed the same way, leaves
  // torn files.
  int torn = 0, in_place_rounds = 0;
  for (int round = 0; round < 10 * kMinRounds && (round < kMinRounds / 2 || torn == 0); ++round) {
    ++in_place_rounds;
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      for (int i = 0;; ++i) {
        std::ofstream in_place(path, std::ios::trunc);
        in_place << format_calibration(i % 2 == 0 ? b : a);
      }
    }
    ::usleep(static_cast<useconds_t>(fraction(rng) * static_cast<double>(save_us)));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    CalibrationFileResult r;
    if (!load_calibration(path, &r)) ++torn;
  }
  std::printf("killed %d writers that overwrite in place: %d torn files\n", in_place_rounds, torn);
  EXPECT_GT(torn, 0);
  // A save after them all.
  ASSERT_TRUE(save_calibration(path, b).ok());
  CalibrationFileResult r;
  EXPECT_TRUE(*load_calibration(path, &r) == b);
  EXPECT_TRUE(temporaries_of(path).empty());
  std::remove(path.c_str());
}

}  // namespace
}  // namespace beaconloc
