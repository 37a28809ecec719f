#include "bsls/session/session.h"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <tuple>

#include "bsls/joining/join_error.h"
#include "bsls/measurement/measurement_error.h"
#include "bsls/session/both_sides.h"

namespace bsls::session {
namespace {

using pattern::Side;

std::string FrameName(Side side) { return std::string(pattern::ToString(side)) + " frame"; }
SessionPart FramePart(Side side) {
  return side == Side::kLeft ? SessionPart::kLeftFrame : SessionPart::kRightFrame;
}

// Thesis 5.2: one side decoded and reconstructed; SessionError naming the side.
reconstruction::SideOutcome ReconstructOneSide(const cv::Mat& grey, Side side,
                                               const calibration::SideCalibration& calibration,
                                               const reconstruction::SidePipelineParams& params,
                                               const Cancellation& cancel) {
  reconstruction::SideOutcome outcome;
  try {
    outcome = reconstruction::ProcessSide(grey, side, &calibration, params, cancel);
  } catch (const std::invalid_argument& e) {
    throw SessionError(SessionErrorReason::kInvalidInput, FramePart(side),
                       FrameName(side) + ": " + e.what());
  } catch (const reconstruction::ReconstructionError& e) {
    throw SessionError(SessionErrorReason::kNotProcessed, FramePart(side),
                       FrameName(side) + ": " + e.what());
  }
  if (!outcome.decode.ok)
    throw SessionError(SessionErrorReason::kNotProcessed, FramePart(side),
                       FrameName(side) + ": " + outcome.decode.error);
  if (!outcome.surface)
    throw SessionError(SessionErrorReason::kNotProcessed, FramePart(side),
                       FrameName(side) + ": no surface was reconstructed");
  return outcome;
}

nlohmann::json SideJson(const reconstruction::SideOutcome& s, const std::string& name) {
  const reconstruction::ReconstructionReport& r = s.report;
  return {{"image", name},
          {"junctions", s.decode.junctions.size()},
          {"lines", s.decode.lines.size()},
          {"q_absolute", s.decode.q_absolute},
          {"q_note", s.rows_note},
          {"vertices", r.vertices},
          {"triangles", r.triangles},
          {"bridged", r.bridged_samples},
          {"decode_ms", s.decode.times.total_ms},
          {"reconstruct_ms", r.time_ms}};
}

}  // namespace

void WorkObserver::Report(std::string_view stage, double fraction) const {
  if (progress) progress(stage, fraction);
}

void WorkObserver::CheckCancelled(std::string_view stage) const {
  if (cancelled && cancelled()) throw Cancelled("cancelled before " + std::string(stage));
}

SessionOutcome ReconstructSession(const cv::Mat& left, const calibration::SideCalibration& left_cal,
                                  const cv::Mat& right,
                                  const calibration::SideCalibration& right_cal,
                                  const SessionParams& params, const WorkObserver& observer) {
  const auto start = std::chrono::steady_clock::now();
  if (left_cal.side != Side::kLeft)
    throw SessionError(SessionErrorReason::kInvalidInput, SessionPart::kLeftCalibration,
                       "left calibration: is a calibration of the right side");
  if (right_cal.side != Side::kRight)
    throw SessionError(SessionErrorReason::kInvalidInput, SessionPart::kRightCalibration,
                       "right calibration: is a calibration of the left side");
  std::string why;
  if (!params.measurements.IsValid(&why))
    throw SessionError(SessionErrorReason::kInvalidInput, SessionPart::kMeasurements,
                       "measurements: " + why);
  if (!params.join_params.IsValid(&why))
    throw SessionError(SessionErrorReason::kInvalidInput, SessionPart::kJoin, "join: " + why);

  SessionOutcome out;
  out.shared_frame = calibration::SharesWorldFrame(left_cal, right_cal, &out.shared_frame_note);
  if (params.join == JoinMode::kShared && !out.shared_frame)
    throw SessionError(SessionErrorReason::kInvalidInput, SessionPart::kCalibrations,
                       "the calibrations do not share a world frame: " + out.shared_frame_note);
  if (out.shared_frame) out.shared_frame_note.clear();
  out.by_features =
      params.join == JoinMode::kFeatures || (params.join == JoinMode::kAuto && !out.shared_frame);

  reconstruction::SidePipelineParams side_params = params.side;
  side_params.reconstruct = true;
  // Each side has a core of its own: no third thread measuring ahead.
  side_params.decode.measure_ahead = false;
  const double measure_share = params.measurements.empty() ? 0.0 : 0.15;
  observer.CheckCancelled("the sides");
  const Cancellation cancel = observer.cancellation();
  observer.Report("both sides", 0.0);
  // The sides are independent until the join: one core each.
  std::tie(out.left, out.right) = RunBothSides(
      [&] { return ReconstructOneSide(left, Side::kLeft, left_cal, side_params, cancel); },
      [&] { return ReconstructOneSide(right, Side::kRight, right_cal, side_params, cancel); });
  observer.CheckCancelled("the join");
  observer.Report("join", 0.8 - measure_share);
  try {
    out.joined = out.by_features ? joining::JoinByFeatures(*out.left.surface, *out.right.surface,
                                                           params.join_params, cancel)
                                 : joining::JoinSharedFrame(*out.left.surface, *out.right.surface,
                                                            params.join_params, cancel);
  } catch (const joining::JoinError& e) {
    throw SessionError(SessionErrorReason::kNotProcessed, SessionPart::kJoin,
                       std::string("join: ") + e.what());
  }
  if (!params.measurements.empty()) {
    observer.CheckCancelled("the measurements");
    observer.Report("measure", 1.0 - measure_share);
    try {
      out.measurements = measurement::MeasurePlan(out.joined.mesh, params.measurements, cancel);
    } catch (const measurement::MeasurementError& e) {
      throw SessionError(SessionErrorReason::kNotProcessed, SessionPart::kMeasurements,
                         std::string("measurements: ") + e.what());
    }
  }
  out.total_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

nlohmann::json SessionReport(const SessionOutcome& o, const std::string& left_name,
                             const std::string& right_name) {
  const Eigen::AngleAxisd rotation(o.joined.rotation);
  const joining::JoinResult& j = o.joined;
  nlohmann::json report = {
      {"left", SideJson(o.left, left_name)},
      {"right", SideJson(o.right, right_name)},
      {"join",
       {{"method", o.by_features ? "features+icp" : "shared-frame"},
        {"shared_frame", o.shared_frame},
        {"shared_frame_note", o.shared_frame_note},
        {"seam_rms_mm", j.seam.rms_mm},
        {"seam_max_mm", j.seam.max_mm},
        {"seam_samples", j.seam.samples},
        {"rotation_deg", rotation.angle() * 180.0 / M_PI},
        {"translation_mm", {j.translation.x(), j.translation.y(), j.translation.z()}},
        {"icp_iterations", j.iterations},
        {"zipper_triangles", j.zipper_triangles}}},
      {"vertices", j.mesh.VertexCount()},
      {"triangles", j.mesh.faces.size()},
      {"total_ms", o.total_ms}};
  if (o.measurements) report["measurements"] = o.measurements->report;
  return report;
}

}  // namespace bsls::session
