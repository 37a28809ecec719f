// The figures of a side calibration as JSON (`bsls calibrate --report`, the
// processing service's calibration-report.json): per-view and overall
// residuals (camera RMS per target view, plane and projector-matrix RMS per
// screen view, ray residual per cross view), the views dropped and why, the
// planes' fit, the projector's pose, the uncertainties and the stage times.
// Devices are laid out as the simulator's truth.json (intrinsics, row-major
// world -> device rotation, translation in mm), so a calibration can be
// compared with the truth directly.
#ifndef BSLS_CALIBRATION_CALIBRATION_REPORT_H_
#define BSLS_CALIBRATION_CALIBRATION_REPORT_H_

#include <nlohmann/json.hpp>

#include "bsls/calibration/side_calibration.h"

namespace bsls::calibration {

// The report of `calibration`; units in every key (mm, px, deg, ms).
nlohmann::json CalibrationReport(const SideCalibration& calibration);

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_CALIBRATION_REPORT_H_
