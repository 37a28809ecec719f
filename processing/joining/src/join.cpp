#include "bsls/joining/join.h"

#include "bsls/joining/stripe_curve.h"

namespace bsls::joining {
namespace {

// A reference line needs a segment at least to be matched or measured on.
constexpr std::size_t kMinReferenceVertices = 2;

void CheckParams(const JoinParams& params) {
  std::string why;
  if (!params.IsValid(&why))
    throw JoinError(JoinError::Reason::kInvalidInput, "parameters: " + why);
}

// The side's reference line, after checking the mesh; throws naming `side`.
StripeCurve ReferenceLine(const geometry::SurfaceMesh& mesh, const std::string& side,
                          const JoinParams& params) {
  std::string why;
  if (!mesh.IsValid(&why))
    throw JoinError(JoinError::Reason::kInvalidInput, side + " mesh: " + why);
  if (mesh.positions.empty())
    throw JoinError(JoinError::Reason::kInvalidInput, side + " mesh: empty (no vertices)");
  if (mesh.line.empty()) {
    throw JoinError(JoinError::Reason::kNoReferenceLine,
                    side + " mesh: no line labels, so no reference line to join on");
  }
  StripeCurve curve = StripeCurve::FromMesh(mesh, params.reference_line, params.max_line_gap_mm);
  if (curve.size() < kMinReferenceVertices) {
    throw JoinError(
        JoinError::Reason::kNoReferenceLine,
        side + " mesh: " + std::to_string(curve.size()) +
            " vertices on the reference line p = " + std::to_string(params.reference_line) +
            " (need " + std::to_string(kMinReferenceVertices) + ")");
  }
  return curve;
}

geometry::SurfaceMesh Moved(const geometry::SurfaceMesh& mesh, const Eigen::Isometry3d& transform) {
  geometry::SurfaceMesh moved = mesh;
  for (Eigen::Vector3d& p : moved.positions) p = transform * p;
  for (Eigen::Vector3d& n : moved.normals) n = transform.linear() * n;
  return moved;
}

void Stitch(const geometry::SurfaceMesh& left, const geometry::SurfaceMesh& right_in_left,
            const JoinParams& params, JoinResult* result) {
  StitchResult stitched = StitchAlongReferenceLine(left, right_in_left, params.reference_line,
                                                   params.max_line_gap_mm, params.stitch);
  result->mesh = std::move(stitched.mesh);
  result->right_vertex_offset = stitched.right_vertex_offset;
  result->zipper_triangles = stitched.zipper_triangles;
  result->skipped_zipper_triangles = stitched.skipped_zipper_triangles;
}

}  // namespace

bool JoinParams::IsValid(std::string* error) const {
  std::string why;
  auto fail = [&](const std::string& text) {
    if (error) *error = text;
    return false;
  };
  if (reference_line < 0) return fail("reference_line must be >= 0");
  if (!(max_line_gap_mm > 0.0)) return fail("max_line_gap_mm must be > 0");
  if (!features.IsValid(&why)) return fail("features: " + why);
  if (!icp.IsValid(&why)) return fail("icp: " + why);
  if (!stitch.IsValid(&why)) return fail("stitch: " + why);
  return true;
}

JoinResult JoinSharedFrame(const geometry::SurfaceMesh& left, const geometry::SurfaceMesh& right,
                           const JoinParams& params, const Cancellation& cancel) {
  CheckParams(params);
  const StripeCurve left_line = ReferenceLine(left, "left", params);
  const StripeCurve right_line = ReferenceLine(right, "right", params);
  cancel.ThrowIfRequested("the reference lines");
  JoinResult result;
  Stitch(left, right, params, &result);
  result.seam = MeasureSeam(left_line, right_line, params.stitch);
  return result;
}

JoinResult JoinByFeatures(const geometry::SurfaceMesh& left, const geometry::SurfaceMesh& right,
                          const JoinParams& params, const Cancellation& cancel) {
  CheckParams(params);
  const StripeCurve left_line = ReferenceLine(left, "left", params);
  const StripeCurve right_line = ReferenceLine(right, "right", params);
  cancel.ThrowIfRequested("the reference lines");
  JoinResult result;
  // Thesis 5.2.2: nose and mouth on each side's common line.
  result.left_features = FindLineFeatures(left_line, params.features, "left");
  result.right_features = FindLineFeatures(right_line, params.features, "right");
  const std::vector<Eigen::Vector3d> left_points = result.left_features.ControlPoints();
  const std::vector<Eigen::Vector3d> right_points = result.right_features.ControlPoints();
  // Thesis 5.2.2 steps 1-3 (line the right side's features up with the
  // left's) as a rigid least-squares fit: both sides are metric.
  const auto initial = RigidFromPairs(right_points, left_points);
  if (!initial) {
    throw JoinError(JoinError::Reason::kFeaturesNotFound,
                    "right mesh: nose, lips and mouth are collinear on one of the sides' "
                    "reference lines; they do not fix a rigid transform");
  }
  const double right_span = (right_points[0] - right_points[2]).norm();
  result.feature_scale =
      right_span > 0.0 ? (left_points[0] - left_points[2]).norm() / right_span : 0.0;
  result.initial_rotation = initial->linear();
  result.initial_translation = initial->translation();
  // Refinement on the whole common line.
  const IcpResult icp = AlignToCurve(left_line, right_line.points(), *initial, params.icp, cancel);
  if (!icp.converged) {
    throw JoinError(
        JoinError::Reason::kNotConverged,
        "right mesh: aligning its reference line onto the left's failed: " + icp.failure);
  }
  result.rotation = icp.transform.linear();
  result.translation = icp.transform.translation();
  result.iterations = icp.iterations;
  result.icp_rms_mm = icp.rms_mm;
  cancel.ThrowIfRequested("the ICP alignment");
  Stitch(left, Moved(right, icp.transform), params, &result);
  result.seam = MeasureSeam(left_line, right_line.Transformed(icp.transform), params.stitch);
  return result;
}

}  // namespace bsls::joining
