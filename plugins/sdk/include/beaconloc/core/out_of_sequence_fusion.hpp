#pragma once
// Measurements fused at their own stamp however late they arrive. A range reaches the localizer
// after newer odometry has (the decoder is one more hop, a beacon's radio and the TOF add their
// own delay); fusing it at arrival would apply it to a pose the robot has since left. This keeps
// the last horizon_ns of odometry and measurements, in stamp order, with copies of the estimator
// (checkpoints) every few odometry samples. A late measurement rolls the estimator back to the
// newest checkpoint at or before its stamp and everything after it is replayed in stamp order,
// so the result is the one in-order delivery gives, to the last bit.
//
// Processing order is stamp order; at equal stamps odometry first, then measurements in the
// order they arrived. (A measurement stamped ahead of the newest odometry, within the horizon,
// keeps its place when the odometry catches up, as in-order delivery would have it.) Estimators
// see exactly the calls they would see in order, so each keeps its own rule for a measurement
// between two odometry samples (range_ekf fuses it at the odometry stamp before it, with the
// receiver moved to where the robot was at the range's stamp; ukf_lrf holds it and fuses it at
// its own stamp).
//
// Only the verdict of a measurement's first application is returned (and counted by the
// localizer); the verdicts of events re-applied during a replay are not counted again. What an
// estimator reports on its own during a replay is passed on: associations (a replayed
// association repeats one already reported; the evaluation scores each range once) and deferred
// rejections (a held measurement whose fusion fails again is counted again).
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/limits.hpp"

namespace beaconloc {

struct OutOfSequenceOptions {
  // How late a measurement may be, against the newest odometry stamp (core/limits.hpp). Older
  // ones are refused (too_late).
  StampNs horizon_ns = kMeasurementHorizonNs;
  // A checkpoint every this many odometry samples: 5 = 50 ms at 100 Hz, so a replay re-runs at
  // most 4 odometry steps more than it must, and 12 copies cover the horizon.
  int checkpoint_every = 5;
};

class OutOfSequenceFusion {
 public:
  OutOfSequenceFusion(std::unique_ptr<Estimator> estimator, OutOfSequenceOptions options = {});

  void set_beacon_map(const BeaconMap& map);
  // Odometry moves the time line on; a measurement (range, scan, raw time of flight) is fused at
  // its own stamp (stamp_of), or refused too_late / ahead_of_odometry.
  InputResult push(EstimatorInput input);
  // A restart from a given pose forgets the history: nothing before it is replayed. It takes
  // effect at the estimator's own time (its newest odometry), never at the pose's stamp, which
  // comes from another clock (an operator's, rviz2's): before the first odometry sample the pose
  // is placed again when that sample starts the time line, so that a stamp far ahead cannot keep
  // the pose "ok" for as long as the robot's clock takes to reach it. A negative stamp is
  // refused (invalid_stamp).
  InputResult reset(StampNs stamp_ns, const Pose2& pose_map_base, const Cov3& covariance);

  const Estimator& estimator() const { return *estimator_; }
  // A calibration found before (Estimator::use_calibration), given to the estimator and to every
  // copy a replay may start from, so that a late measurement does not roll it back. Whether the
  // estimator took it.
  bool use_calibration(const BeaconCalibration& calibration);
  // The estimator's newest calibration when it changed since last asked (a replay that finds a
  // calibration of its own again reports it again; one given by use_calibration is not news).
  std::optional<BeaconCalibration> take_calibration_update();
  std::vector<Estimator::Association> take_associations();
  std::vector<Rejection> take_deferred_rejections();

  std::optional<StampNs> newest_odometry_ns() const { return newest_odometry_ns_; }
  std::uint64_t replays() const { return replays_; }
  std::uint64_t replayed_odometry_steps() const { return replayed_odometry_steps_; }

 private:
  struct Event {
    EstimatorInput input;
    StampNs stamp_ns = 0;                   // stamp_of(input)
    std::unique_ptr<Estimator> checkpoint;  // the estimator right after this odometry sample
  };
  InputResult odometry(Event event);
  InputResult measurement(Event event);
  InputResult apply(const Event& event);
  void collect_outputs();
  void forget_before_horizon();

  std::unique_ptr<Estimator> estimator_;
  OutOfSequenceOptions options_;
  // The estimator before history_.front(), and the stamp before which nothing can be replayed.
  std::unique_ptr<Estimator> base_;
  StampNs base_stamp_ns_;
  std::deque<Event> history_;  // processing order
  std::optional<StampNs> newest_odometry_ns_;
  struct Placement {
    Pose2 pose_map_base;
    Cov3 covariance;
  };
  std::optional<Placement> placed_before_odometry_;  // reset() before the time line began
  int odometry_since_checkpoint_ = 0;
  std::vector<Estimator::Association> associations_;
  std::vector<Rejection> deferred_rejections_;
  std::optional<BeaconCalibration> calibration_update_;
  std::uint64_t replays_ = 0;
  std::uint64_t replayed_odometry_steps_ = 0;
};

}  // namespace beaconloc
