// From a side's calibration (bsls/calibration/side_calibration.h) to what
// triangulation needs: the camera, the light planes of one of the two
// projector models, the projector matrix for junctions, and the sigmas of the
// calibration for the uncertainty of every point. Also the even offset that
// turns a decode's relative q into the slide row (contracts section 2), found
// through the projector matrix.
//
// Frames and units: world mm (contracts section 3); image pixels; slide (s, t)
// in line pitches d.
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_RECONSTRUCTION_CALIBRATED_MODEL_H_
#define BSLS_RECONSTRUCTION_CALIBRATED_MODEL_H_

#include <Eigen/Core>
#include <opencv2/core/types.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bsls/calibration/side_calibration.h"
#include "bsls/decoder/decoder.h"
#include "bsls/reconstruction/triangulation.h"

namespace bsls::reconstruction {

// Which light-plane model of the calibration triangulates line samples.
enum class PlaneModelKind {
  kPerspective,  // thesis 6.2.2: a pencil of planes through the projector (default)
  kParallel,     // thesis 6.2.1: parallel planes, the thesis's simpler model
};

// The triangulation model of `calibration`: its camera, the light planes of
// `planes`, its projector matrix when fitted, and UncertaintyParams from its
// measured sigmas (stripe-centre scatter, target reprojection, plane RMS,
// projector residual); a sigma the calibration did not measure keeps the
// UncertaintyParams default.
TriangulationModel ModelOfCalibration(const calibration::SideCalibration& calibration,
                                      PlaneModelKind planes = PlaneModelKind::kPerspective);

// The triangulation model of a camera and a projector known exactly (e.g. the
// simulator's rig): light planes from the projector (LightPlanesOfProjector)
// and the projector for junctions; default uncertainty params.
TriangulationModel ModelOfKnownDevices(pattern::Side side, const geometry::PinholeModel& camera,
                                       const geometry::PinholeModel& projector);

// The calibration a perfect session on a camera and a projector known
// exactly (e.g. the simulator's rig) would give: the camera, the projector
// as its matrix, the perspective light planes fitted (thesis 6.2.2) to
// points of the projector's planes between the heights of `screen_z_mm`
// (listed as screen views), for a frame of width x height and `pattern`.
// Without measuring errors; for reports and tests that need a calibration of
// a drawn rig.
calibration::SideCalibration CalibrationOfKnownDevices(
    pattern::Side side, const geometry::PinholeModel& camera,
    const geometry::PinholeModel& projector, const pattern::PatternSpec& pattern, int width,
    int height, const std::vector<double>& screen_z_mm = {0.0, 150.0});

struct SlideRowParams {
  // A junction agrees with the offset when its projected slide row lies
  // within this many rows of (q + offset).
  double agreement_rows = 0.5;
  // At least this fraction of the junctions used must agree.
  double min_agreement = 0.8;
  int min_junctions = 5;  // seen (not interpolated) junctions needed, >= 1

  // True when the numbers are in range; otherwise names the field.
  bool IsValid(std::string* error) const;
};

// Where the camera ray through `image` meets the light plane of line p (the
// calibration's perspective model), and where that point falls on the
// slide through its projector matrix (x: s, y: the slide row t); nullopt
// where the ray misses the plane or the projector, or the calibration has
// no projector matrix.
struct SlidePoint {
  Eigen::Vector3d world;
  Eigen::Vector2d slide;
};
std::optional<SlidePoint> JunctionOnSlide(const calibration::SideCalibration& calibration,
                                          const cv::Point2d& image, int p);
// The same for the camera ray through the junction (its BackProject), when
// one junction is tried on several lines.
std::optional<SlidePoint> JunctionOnSlide(const calibration::SideCalibration& calibration,
                                          const geometry::Ray& ray, int p);

// The even offset nearest the median of `residues` (slide row t - q, one per
// junction; reordered); `residues` must not be empty.
int EvenRowOffset(std::vector<double>* residues);

// The even offset that makes the relative q of `decode` the slide row: each
// seen junction is triangulated on the light plane of its p, projected into
// the slide by the calibration's projector matrix, and its slide row t
// compared with q; the median of t - q, rounded to the nearest even integer,
// is the offset. nullopt, with the reason in `why`, when the calibration has
// no projector matrix (no reference views), too few junctions triangulate, or
// fewer than min_agreement of them agree with the offset.
std::optional<int> SlideRowOffset(const decoder::DecodeResult& decode,
                                  const calibration::SideCalibration& calibration, std::string* why,
                                  const SlideRowParams& params = {});

// Adds the even `q_offset` to every junction's q of `decode` and marks its
// rows absolute (as decoder::DecodeParams::q_offset would have).
// std::invalid_argument for an odd offset or rows already absolute.
void MakeRowsAbsolute(int q_offset, decoder::DecodeResult* decode);

}  // namespace bsls::reconstruction

#endif  // BSLS_RECONSTRUCTION_CALIBRATED_MODEL_H_
