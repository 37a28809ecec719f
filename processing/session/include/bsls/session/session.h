// A face session from two frames to one measured surface (thesis 5.2, 7.2):
// each side decoded and reconstructed with its calibration
// (side_pipeline.h), the two joined along the reference line — merged
// directly when the calibrations share a world frame (contracts section 4),
// otherwise matched on the common line's nose and mouth (thesis 5.2.2) and
// refined by ICP — and the requested figures measured on the joined surface.
// The chain `bsls reconstruct` and the processing service share.
//
// Frames and units: image pixels in, world millimetres out (contracts 3);
// the joined mesh is in the left side's frame.
// Thread-safety: ReconstructSession is a pure function of its arguments (it
// runs the two sides on two threads, the left on one of its own); the
// observer's callbacks run on the calling thread.
#ifndef BSLS_SESSION_SESSION_H_
#define BSLS_SESSION_SESSION_H_

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "bsls/calibration/side_calibration.h"
#include "bsls/common/cancellation.h"
#include "bsls/joining/join.h"
#include "bsls/measurement/plan.h"
#include "bsls/reconstruction/side_pipeline.h"

namespace bsls::session {

// The caller gave up (WorkObserver::cancelled said so); nothing is returned.
using Cancelled = bsls::Cancelled;

// Why a session could not be reconstructed.
enum class SessionErrorReason {
  kInvalidInput,  // a calibration of the wrong side, frames of the wrong size, bad params
  kNotProcessed,  // the input was read but gives no surface (no reference line, no join)
};

// The part of a session an error is about.
enum class SessionPart {
  kLeftFrame,
  kRightFrame,
  kLeftCalibration,
  kRightCalibration,
  kCalibrations,  // the pair (they do not share a world frame)
  kJoin,
  kMeasurements,
};

// A session that cannot be reconstructed; what() names the part ("left
// frame", "right calibration", "join", "measurements") and the reason.
class SessionError : public std::runtime_error {
 public:
  SessionError(SessionErrorReason reason, SessionPart part, const std::string& message)
      : std::runtime_error(message), reason_(reason), part_(part) {}
  SessionErrorReason reason() const { return reason_; }
  SessionPart part() const { return part_; }

 private:
  SessionErrorReason reason_;
  SessionPart part_;
};

// Progress reports and the question whether to stop, asked between stages.
// Either may be empty.
struct WorkObserver {
  std::function<void(std::string_view stage, double fraction)> progress;
  std::function<bool()> cancelled;

  // The stages' view of `cancelled` (never asks to stop without one).
  Cancellation cancellation() const { return Cancellation(cancelled); }

  // Reports that `stage` starts with `fraction` of the work done.
  void Report(std::string_view stage, double fraction) const;
  // Throws Cancelled (naming `stage`) when the caller gave up.
  void CheckCancelled(std::string_view stage) const;
};

enum class JoinMode {
  kAuto,      // shared frame when the calibrations share one, else features
  kShared,    // the calibrations must share a world frame
  kFeatures,  // thesis 5.2.2 + ICP
};

struct SessionParams {
  reconstruction::SidePipelineParams side;  // reconstruct is forced on
  JoinMode join = JoinMode::kAuto;
  joining::JoinParams join_params;
  measurement::MeasurementPlan measurements;  // empty: nothing measured
};

struct SessionOutcome {
  reconstruction::SideOutcome left;
  reconstruction::SideOutcome right;
  joining::JoinResult joined;
  bool shared_frame = false;      // the calibrations share a world frame
  std::string shared_frame_note;  // why not, when they do not
  bool by_features = false;       // joined by thesis 5.2.2 + ICP
  std::optional<measurement::MeasurementOutcome> measurements;
  double total_ms = 0.0;
};

// Reconstructs, joins and measures one session. Throws SessionError naming
// the part and the reason, Cancelled when the observer says so.
SessionOutcome ReconstructSession(const cv::Mat& left, const calibration::SideCalibration& left_cal,
                                  const cv::Mat& right,
                                  const calibration::SideCalibration& right_cal,
                                  const SessionParams& params, const WorkObserver& observer = {});

// The session's report (report.json): per side (named `left_name`,
// `right_name`), the join and its seam error, the joined mesh's size, the
// time, and the measurements when there are any.
nlohmann::json SessionReport(const SessionOutcome& outcome, const std::string& left_name,
                             const std::string& right_name);

}  // namespace bsls::session

#endif  // BSLS_SESSION_SESSION_H_
