#include "beaconloc/core/out_of_sequence_fusion.hpp"

#include <algorithm>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <utility>

namespace beaconloc {

OutOfSequenceFusion::OutOfSequenceFusion(std::unique_ptr<Estimator> estimator, OutOfSequenceOptions options)
    : estimator_(std::move(estimator)),
      options_(options),
      base_stamp_ns_(std::numeric_limits<StampNs>::min()) {
  if (!estimator_) throw std::invalid_argument("OutOfSequenceFusion needs an estimator");
  if (options_.horizon_ns < 0 || options_.checkpoint_every < 1) {
    throw std::invalid_argument("OutOfSequenceFusion: horizon_ns >= 0 and checkpoint_every >= 1");
  }
  base_ = estimator_->clone();
}

void OutOfSequenceFusion::set_beacon_map(const BeaconMap& map) {
  estimator_->set_beacon_map(map);
  base_->set_beacon_map(map);
  for (auto& e : history_) {
    if (e.checkpoint) e.checkpoint->set_beacon_map(map);
  }
}

bool OutOfSequenceFusion::use_calibration(const BeaconCalibration& calibration) {
  const bool taken = estimator_->use_calibration(calibration);
  if (!taken) return false;
  // The copies hold it as given, not as news: a replay from one does not report it again.
  base_->use_calibration(calibration);
  base_->take_calibration_update();
  for (auto& e : history_) {
    if (!e.checkpoint) continue;
    e.checkpoint->use_calibration(calibration);
    e.checkpoint->take_calibration_update();
  }
  collect_outputs();
  return true;
}

std::optional<BeaconCalibration> OutOfSequenceFusion::take_calibration_update() {
  return std::exchange(calibration_update_, std::nullopt);
}

InputResult OutOfSequenceFusion::apply(const Event& e) {
  const InputResult result = estimator_->push(e.input);
  collect_outputs();  // before any checkpoint: a copy must not carry reports already passed on
  return result;
}

void OutOfSequenceFusion::collect_outputs() {
  for (auto& a : estimator_->take_associations()) associations_.push_back(a);
  for (auto& r : estimator_->take_deferred_rejections()) deferred_rejections_.push_back(std::move(r));
  if (auto c = estimator_->take_calibration_update()) calibration_update_ = std::move(c);
}

InputResult OutOfSequenceFusion::push(EstimatorInput input) {
  Event e;
  e.stamp_ns = stamp_of(input);
  e.input = std::move(input);
  return is_odometry(e.input) ? odometry(std::move(e)) : measurement(std::move(e));
}

InputResult OutOfSequenceFusion::odometry(Event e) {
  const StampNs stamp_ns = e.stamp_ns;
  const InputResult result = apply(e);
  // Only a sample that moved the estimator's time line is kept: an accepted one, or an
  // odometry_gap, which re-anchors it (a replay must do the same). A refused sample changed
  // nothing (non-finite values, a duplicate, out of order) and must not move the horizon.
  if (!result.accepted && result.rejection != Rejection::kOdometryGap) return result;
  if (newest_odometry_ns_ && stamp_ns <= *newest_odometry_ns_) return result;
  newest_odometry_ns_ = stamp_ns;
  if (placed_before_odometry_) {
    // The time line begins: the pose given before it is the estimator's pose from now on.
    const Placement p = *placed_before_odometry_;
    reset(stamp_ns, p.pose_map_base, p.covariance);
    return result;
  }
  if (odometry_since_checkpoint_ == 0) e.checkpoint = estimator_->clone();
  odometry_since_checkpoint_ = (odometry_since_checkpoint_ + 1) % options_.checkpoint_every;
  history_.push_back(std::move(e));
  forget_before_horizon();
  return result;
}

InputResult OutOfSequenceFusion::measurement(Event event) {
  if (!newest_odometry_ns_) {
    // Before any odometry there is no time line to place it on: as it comes, and not kept (a
    // robot whose odometry never comes must not grow a history).
    return apply(event);
  }
  if (event.stamp_ns < base_stamp_ns_ ||
      older_than(event.stamp_ns, *newest_odometry_ns_, options_.horizon_ns)) {
    return InputResult::rejected(Rejection::kTooLate);
  }
  // A stamp further ahead of the odometry than the horizon is a clock fault (a time jump), not a
  // measurement the odometry will catch up with.
  if (older_than(*newest_odometry_ns_, event.stamp_ns, options_.horizon_ns)) {
    return InputResult::rejected(Rejection::kAheadOfOdometry);
  }
  // After every event stamped at or before it (odometry of the same stamp first). Searched from
  // the newest: a measurement slightly ahead of the odometry stays where it was processed.
  auto position = history_.end();
  while (position != history_.begin() && std::prev(position)->stamp_ns > event.stamp_ns) --position;
  if (position == history_.end()) {
    const InputResult result = apply(event);
    history_.push_back(std::move(event));
    return result;
  }

  // Late: back to the newest checkpoint before its place, then everything after it again.
  const std::size_t inserted = static_cast<std::size_t>(position - history_.begin());
  std::size_t first = 0;
  const Estimator* restore = base_.get();
  for (std::size_t i = inserted; i-- > 0;) {
    if (history_[i].checkpoint) {
      restore = history_[i].checkpoint.get();
      first = i + 1;
      break;
    }
  }
  estimator_ = restore->clone();
  history_.insert(position, std::move(event));
  ++replays_;
  InputResult result;
  for (std::size_t i = first; i < history_.size(); ++i) {
    Event& e = history_[i];
    const InputResult r = apply(e);
    if (i == inserted) {
      result = r;
    } else if (is_odometry(e.input)) {
      ++replayed_odometry_steps_;
    }
    if (e.checkpoint) e.checkpoint = estimator_->clone();
  }
  return result;
}

InputResult OutOfSequenceFusion::reset(StampNs stamp_ns, const Pose2& pose_map_base, const Cov3& covariance) {
  if (stamp_ns < 0) return InputResult::rejected(Rejection::kInvalidStamp);
  const InputResult result = estimator_->reset(stamp_ns, pose_map_base, covariance);
  collect_outputs();
  if (!result.accepted) return result;
  // What came before the restart is not replayed over it.
  history_.clear();
  placed_before_odometry_.reset();
  if (!newest_odometry_ns_) placed_before_odometry_ = Placement{pose_map_base, covariance};
  base_ = estimator_->clone();
  // From the estimator's own time (the newest odometry), not the pose's stamp: an operator's
  // clock may run ahead of the robot's.
  base_stamp_ns_ = newest_odometry_ns_.value_or(stamp_ns);
  odometry_since_checkpoint_ = 0;
  return result;
}

void OutOfSequenceFusion::forget_before_horizon() {
  // The newest checkpoint at or before the horizon becomes the base; what precedes it goes.
  std::size_t last = history_.size();
  for (std::size_t i = 0;
       i < history_.size() && older_than(history_[i].stamp_ns, *newest_odometry_ns_, options_.horizon_ns);
       ++i) {
    if (history_[i].checkpoint) last = i;
  }
  if (last == history_.size()) return;
  base_ = std::move(history_[last].checkpoint);
  base_stamp_ns_ = history_[last].stamp_ns;
  history_.erase(history_.begin(), history_.begin() + static_cast<std::ptrdiff_t>(last) + 1);
}

std::vector<Estimator::Association> OutOfSequenceFusion::take_associations() {
  std::vector<Estimator::Association> out;
  out.swap(associations_);
  return out;
}

std::vector<Rejection> OutOfSequenceFusion::take_deferred_rejections() {
  std::vector<Rejection> out;
  out.swap(deferred_rejections_);
  return out;
}

}  // namespace beaconloc
