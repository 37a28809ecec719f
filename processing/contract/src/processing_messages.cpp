#include "bsls/contract/processing_messages.h"

#include <optional>

#include "bsls/decoder/decoder.h"

namespace bsls::contract {
namespace {

// Refuses a number in an enum field that its .proto does not define.
void RequireDefined(int value, bool (*is_valid)(int), const std::string& field) {
  if (!is_valid(value))
    throw MessageError(field + ": " + std::to_string(value) + " is not one of the field's values");
}

Eigen::Vector2d PointOf(const v1::PointXY& p) { return {p.x(), p.y()}; }

measurement::Polygon2d PolygonOf(const v1::Polygon& polygon) {
  measurement::Polygon2d out;
  for (const v1::PointXY& p : polygon.points()) out.push_back(PointOf(p));
  return out;
}

void AddPoint(const Eigen::Vector2d& p, v1::PointXY* out) {
  out->set_x(p.x());
  out->set_y(p.y());
}

void AddPolygon(const measurement::Polygon2d& polygon, v1::Polygon* out) {
  for (const Eigen::Vector2d& p : polygon) AddPoint(p, out->add_points());
}

}  // namespace

pattern::Side SideOf(v1::Side side, const std::string& field) {
  if (side == v1::SIDE_LEFT) return pattern::Side::kLeft;
  if (side == v1::SIDE_RIGHT) return pattern::Side::kRight;
  throw MessageError(field + ": must be SIDE_LEFT or SIDE_RIGHT");
}

v1::Side ToProto(pattern::Side side) {
  return side == pattern::Side::kLeft ? v1::SIDE_LEFT : v1::SIDE_RIGHT;
}

reconstruction::SidePipelineParams SideParams(const v1::DecodeOptions& decode,
                                              const v1::SurfaceOptions& surface) {
  RequireDefined(decode.method(), v1::DecodeOptions::Method_IsValid, "decode.method");
  RequireDefined(decode.chain(), v1::DecodeOptions::Chain_IsValid, "decode.chain");
  RequireDefined(surface.plane_model(), v1::SurfaceOptions::PlaneModel_IsValid,
                 "surface.plane_model");
  RequireDefined(surface.strips(), v1::SurfaceOptions::StripMethod_IsValid, "surface.strips");
  reconstruction::SidePipelineParams params;
  params.decode.extraction.method = decode.method() == v1::DecodeOptions::METHOD_THESIS
                                        ? extraction::ExtractionMethod::kThesis
                                        : extraction::ExtractionMethod::kModern;
  params.decode.interpretation.enable_repair = !decode.no_repair();
  std::optional<decoder::DecodeChain> named;
  if (decode.chain() == v1::DecodeOptions::CHAIN_TRACKS) named = decoder::DecodeChain::kTracks;
  if (decode.chain() == v1::DecodeOptions::CHAIN_SKELETON) named = decoder::DecodeChain::kSkeleton;
  std::string why;
  if (!decoder::ChainFor(named, params.decode, &why)) throw MessageError("decode.chain: " + why);
  params.chain = named;
  params.planes = surface.plane_model() == v1::SurfaceOptions::PLANE_MODEL_PARALLEL
                      ? reconstruction::PlaneModelKind::kParallel
                      : reconstruction::PlaneModelKind::kPerspective;
  params.reconstruction.smooth_lines = surface.smooth_lines();
  params.reconstruction.mesh.strips = surface.strips() == v1::SurfaceOptions::STRIP_METHOD_ROW_PAIRS
                                          ? reconstruction::StripMethod::kRowPairs
                                          : reconstruction::StripMethod::kStitched;
  return params;
}

session::JoinMode JoinModeOf(v1::ReconstructSessionRequest::Join join) {
  RequireDefined(join, v1::ReconstructSessionRequest::Join_IsValid, "join");
  switch (join) {
    case v1::ReconstructSessionRequest::JOIN_SHARED:
      return session::JoinMode::kShared;
    case v1::ReconstructSessionRequest::JOIN_FEATURES:
      return session::JoinMode::kFeatures;
    default:
      return session::JoinMode::kAuto;
  }
}

measurement::MeasurementPlan PlanOf(const v1::MeasurementPlan& m, int max_figures) {
  const int figures = m.heights_size() + m.distances_size() + m.areas_size() + m.lesions_size();
  if (figures > max_figures)
    throw MessageError("measurements: " + std::to_string(figures) + " figures, at most " +
                       std::to_string(max_figures));
  RequireDefined(m.reference(), v1::MeasurementPlan::Reference_IsValid, "measurements.reference");
  measurement::MeasurementPlan plan;
  for (const v1::PointXY& h : m.heights()) plan.heights.push_back(PointOf(h));
  for (int i = 0; i < m.distances_size(); ++i) {
    if (m.distances(i).points_size() != 2)
      throw MessageError("measurements.distances[" + std::to_string(i) +
                         "]: give exactly two points");
    plan.distances.push_back(
        {PointOf(m.distances(i).points(0)), PointOf(m.distances(i).points(1))});
  }
  for (const v1::Polygon& a : m.areas()) plan.areas.push_back(PolygonOf(a));
  for (const v1::Polygon& l : m.lesions()) plan.lesions.push_back(PolygonOf(l));
  switch (m.reference()) {
    case v1::MeasurementPlan::REFERENCE_PLANE:
      plan.lesion.reference = measurement::ReferenceKind::kPlane;
      break;
    case v1::MeasurementPlan::REFERENCE_QUADRIC:
      plan.lesion.reference = measurement::ReferenceKind::kQuadric;
      break;
    default:
      plan.lesion.reference = measurement::ReferenceKind::kCubic;
  }
  if (m.ring_mm() != 0.0) plan.lesion.ring_width_mm = m.ring_mm();
  std::string why;
  if (!plan.IsValid(&why)) throw MessageError("measurements: " + why);
  return plan;
}

v1::MeasurementPlan ToProto(const measurement::MeasurementPlan& plan) {
  v1::MeasurementPlan m;
  for (const Eigen::Vector2d& h : plan.heights) AddPoint(h, m.add_heights());
  for (const auto& d : plan.distances) AddPolygon({d[0], d[1]}, m.add_distances());
  for (const auto& a : plan.areas) AddPolygon(a, m.add_areas());
  for (const auto& l : plan.lesions) AddPolygon(l, m.add_lesions());
  switch (plan.lesion.reference) {
    case measurement::ReferenceKind::kPlane:
      m.set_reference(v1::MeasurementPlan::REFERENCE_PLANE);
      break;
    case measurement::ReferenceKind::kQuadric:
      m.set_reference(v1::MeasurementPlan::REFERENCE_QUADRIC);
      break;
    default:
      m.set_reference(v1::MeasurementPlan::REFERENCE_CUBIC);
  }
  m.set_ring_mm(plan.lesion.ring_width_mm);
  return m;
}

void FillSide(const reconstruction::SideOutcome& o, pattern::Side side, v1::SideSummary* out) {
  const decoder::DecodeResult& d = o.decode;
  out->set_side(ToProto(side));
  out->set_junctions(static_cast<std::uint32_t>(d.junctions.size()));
  std::uint32_t interpolated = 0;
  for (const auto& j : d.junctions) interpolated += j.interpolated;
  out->set_interpolated_junctions(interpolated);
  out->set_unlabelled_junctions(static_cast<std::uint32_t>(d.unlabelled.size()));
  out->set_lines(static_cast<std::uint32_t>(d.lines.size()));
  out->set_q_absolute(d.q_absolute);
  out->set_rows_note(o.rows_note);
  out->set_repairs(static_cast<std::uint32_t>(d.repairs));
  out->set_vertices(static_cast<std::uint32_t>(o.report.vertices));
  out->set_triangles(static_cast<std::uint32_t>(o.report.triangles));
  out->set_bridged_samples(static_cast<std::uint32_t>(o.report.bridged_samples));
  out->set_label_conflicts(static_cast<std::uint32_t>(d.label_conflicts));
  out->set_islands(static_cast<std::uint32_t>(d.islands));
  out->set_islands_placed(static_cast<std::uint32_t>(d.islands_placed));
  out->set_ruled_out(static_cast<std::uint32_t>(d.ruled_out));
  out->set_dropped_samples(static_cast<std::uint32_t>(o.report.dropped_samples));
  out->set_surface_junctions(static_cast<std::uint32_t>(o.report.junctions));
  out->set_junctions_by_projector(static_cast<std::uint32_t>(o.report.junctions_by_projector));
}

}  // namespace bsls::contract
