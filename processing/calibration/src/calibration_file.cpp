#include "bsls/calibration/calibration_file.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <charconv>
#include <cmath>

#include "bsls/common/atomic_file.h"
#include "calibration_reader.h"

namespace bsls::calibration {
namespace {

// ---------------------------------------------------------------- writing

// Shortest text that reads back as the same double ("6.5", "-0.05",
// "1.0000000000000002"); YAML's .nan / .inf for the others, which the reader
// refuses.
std::string Num(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

void Vec(YAML::Emitter& out, const char* key, const Eigen::VectorXd& v) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (Eigen::Index i = 0; i < v.size(); ++i) out << Num(v(i));
  out << YAML::EndSeq;
}

void Intrinsics(YAML::Emitter& out, const geometry::Intrinsics& in) {
  out << YAML::Key << "intrinsics" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "fx" << YAML::Value << Num(in.fx);
  out << YAML::Key << "fy" << YAML::Value << Num(in.fy);
  out << YAML::Key << "cx" << YAML::Value << Num(in.cx);
  out << YAML::Key << "cy" << YAML::Value << Num(in.cy);
  out << YAML::Key << "k1" << YAML::Value << Num(in.k1);
  out << YAML::Key << "k2" << YAML::Value << Num(in.k2);
  out << YAML::EndMap;
}

void Pose(YAML::Emitter& out, const geometry::Pose& pose) {
  out << YAML::Key << "pose" << YAML::Value << YAML::BeginMap;
  Eigen::Matrix<double, 9, 1> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(3 * i + j) = pose.rotation(i, j);
  Vec(out, "rotation", r);  // row-major, world -> device
  Vec(out, "translation_mm", pose.translation);
  out << YAML::EndMap;
}

template <typename T>
void KeyValue(YAML::Emitter& out, const char* key, const T& value) {
  out << YAML::Key << key << YAML::Value << value;
}

void KeyValue(YAML::Emitter& out, const char* key, double value) {
  out << YAML::Key << key << YAML::Value << Num(value);
}

void StripeReport(YAML::Emitter& out, const StripeFitReport& r) {
  out << YAML::Key << "fit" << YAML::Value << YAML::Flow << YAML::BeginMap;
  KeyValue(out, "points_used", r.points_used);
  KeyValue(out, "points_dropped", r.points_dropped);
  KeyValue(out, "rms_mm", r.rms_mm);
  KeyValue(out, "max_mm", r.max_mm);
  KeyValue(out, "first_pass_rms_mm", r.first_pass_rms_mm);
  out << YAML::EndMap;
}

void CameraSigmas(YAML::Emitter& out, const CameraParameterSigmas& s) {
  out << YAML::Key << "sigmas" << YAML::Value << YAML::BeginMap;
  KeyValue(out, "f_px", s.f_px);
  KeyValue(out, "sx", s.sx);
  KeyValue(out, "fx_px", s.fx_px);
  KeyValue(out, "fy_px", s.fy_px);
  KeyValue(out, "cx_px", s.cx_px);
  KeyValue(out, "cy_px", s.cy_px);
  KeyValue(out, "k1", s.k1);
  KeyValue(out, "k2", s.k2);
  Vec(out, "rotation_rad", s.rotation_rad);
  Vec(out, "translation_mm", s.translation_mm);
  out << YAML::EndMap;
}

// ---------------------------------------------------------------- reading

// Reads nodes, naming the file and the key path in every error: scalars
// and mappings as the head is read (calibration_reader.h), and vectors.
class Reader : public CalibrationReader {
 public:
  using CalibrationReader::CalibrationReader;

  Eigen::VectorXd Vector(const YAML::Node& node, const std::string& key, const std::string& where,
                         int size) const {
    const YAML::Node child = Child(node, key, where, false);
    const std::string path = where.empty() ? key : where + "." + key;
    if (!child.IsSequence() || static_cast<int>(child.size()) != size)
      Fail("", "'" + path + "' must be a list of " + std::to_string(size) + " numbers");
    Eigen::VectorXd v(size);
    for (int i = 0; i < size; ++i) {
      double value = 0.0;
      try {
        value = child[i].as<double>();
      } catch (const YAML::Exception&) {
        Fail("", "'" + path + "' must be a list of " + std::to_string(size) + " numbers");
      }
      if (!std::isfinite(value))
        Fail("", "'" + path + "[" + std::to_string(i) + "]' is not a finite number");
      v(i) = value;
    }
    return v;
  }

  Eigen::Vector3d Vector3(const YAML::Node& node, const std::string& key,
                          const std::string& where) const {
    return Vector(node, key, where, 3);
  }
};

std::string Join(const std::string& where, const std::string& key) {
  return where.empty() ? key : where + "." + key;
}

geometry::Intrinsics ReadIntrinsics(const Reader& r, const YAML::Node& parent,
                                    const std::string& where) {
  const std::string w = Join(where, "intrinsics");
  const YAML::Node n = r.Child(parent, "intrinsics", where);
  geometry::Intrinsics in;
  in.fx = r.Get<double>(n, "fx", w);
  in.fy = r.Get<double>(n, "fy", w);
  in.cx = r.Get<double>(n, "cx", w);
  in.cy = r.Get<double>(n, "cy", w);
  in.k1 = r.Get<double>(n, "k1", w);
  in.k2 = r.Get<double>(n, "k2", w);
  std::string why;
  if (!in.IsValid(&why)) r.Fail(w, why);
  return in;
}

geometry::Pose ReadPose(const Reader& r, const YAML::Node& parent, const std::string& where) {
  const std::string w = Join(where, "pose");
  const YAML::Node n = r.Child(parent, "pose", where);
  geometry::Pose pose;
  const Eigen::VectorXd rot = r.Vector(n, "rotation", w, 9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pose.rotation(i, j) = rot(3 * i + j);
  pose.translation = r.Vector3(n, "translation_mm", w);
  constexpr double kRotationTolerance = 1e-6;
  if (!(pose.rotation * pose.rotation.transpose()).isIdentity(kRotationTolerance) ||
      !(pose.rotation.determinant() > 0.0))
    r.Fail(w, "rotation is not a rotation matrix");
  return pose;
}

StripeFitReport ReadStripeReport(const Reader& r, const YAML::Node& parent,
                                 const std::string& where) {
  const std::string w = Join(where, "fit");
  const YAML::Node n = r.Child(parent, "fit", where);
  StripeFitReport report;
  report.points_used = r.Get<int>(n, "points_used", w);
  report.points_dropped = r.Get<int>(n, "points_dropped", w);
  report.rms_mm = r.Get<double>(n, "rms_mm", w);
  report.max_mm = r.Get<double>(n, "max_mm", w);
  report.first_pass_rms_mm = r.Get<double>(n, "first_pass_rms_mm", w);
  return report;
}

Eigen::Vector3d Unit(const Reader& r, const Eigen::Vector3d& v, const std::string& where) {
  const double n = v.norm();
  if (!(std::abs(n - 1.0) < 1e-6)) r.Fail(where, "must have unit length");
  return v;
}

// Writes the file's identity: format, versions, side, image size, manifest
// hash, pattern and target.
void WriteHeader(YAML::Emitter& out, const SideCalibration& c,
                 const std::string& software_version) {
  KeyValue(out, "format", kCalibrationFormatName);
  KeyValue(out, "format_version", kCalibrationFormatVersion);
  KeyValue(out, "software_version", software_version);
  KeyValue(out, "side", std::string(pattern::ToString(c.side)));
  out << YAML::Key << "image" << YAML::Value << YAML::Flow << YAML::BeginMap;
  KeyValue(out, "width", c.width);
  KeyValue(out, "height", c.height);
  out << YAML::EndMap;
  KeyValue(out, "manifest_sha256", c.manifest_sha256);
  out << YAML::Key << "pattern" << YAML::Value << YAML::Flow << YAML::BeginMap;
  KeyValue(out, "lines", c.pattern.lines);
  KeyValue(out, "rows", c.pattern.rows);
  KeyValue(out, "stroke_width", c.pattern.stroke_width);
  out << YAML::EndMap;
  out << YAML::Key << "target" << YAML::Value << YAML::Flow << YAML::BeginMap;
  KeyValue(out, "rows", c.target.rows);
  KeyValue(out, "cols", c.target.cols);
  KeyValue(out, "pitch_mm", c.target.pitch_mm);
  KeyValue(out, "square_mm", c.target.square_mm);
  out << YAML::EndMap;
}

// Writes the "camera" mapping: model, report and per-view residuals.
void WriteCamera(YAML::Emitter& out, const SideCalibration& c) {
  const CameraCalibrationReport& cr = c.camera.report;
  out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  Intrinsics(out, c.camera.model.intrinsics());
  Pose(out, c.camera.model.pose());
  out << YAML::Key << "report" << YAML::Value << YAML::BeginMap;
  KeyValue(out, "points", cr.num_points);
  KeyValue(out, "views", cr.num_views);
  KeyValue(out, "rms_px", cr.rms_px);
  KeyValue(out, "max_px", cr.max_px);
  KeyValue(out, "rms_mm", cr.rms_mm);
  KeyValue(out, "max_mm", cr.max_mm);
  KeyValue(out, "residual_sigma_px", cr.residual_sigma_px);
  KeyValue(out, "f_px", cr.f_px);
  KeyValue(out, "sx", cr.sx);
  KeyValue(out, "initialisation",
           cr.initialisation == CameraInitialisation::kTsai ? "tsai" : "dlt");
  KeyValue(out, "iterations", cr.iterations);
  KeyValue(out, "converged", cr.converged);
  if (cr.sigmas) CameraSigmas(out, *cr.sigmas);
  out << YAML::EndMap;
  out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
  for (size_t i = 0; i < c.camera_views.size(); ++i) {
    const CameraViewReport& v = c.camera_views[i];
    out << YAML::Flow << YAML::BeginMap;
    KeyValue(out, "image", v.image.string());
    KeyValue(out, "z_mm", v.z_mm);
    KeyValue(out, "rms_px", v.rms_px);
    KeyValue(out, "rms_mm", v.rms_mm);
    KeyValue(out, "max_grid_residual", v.max_grid_residual);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
}

// Writes the "matrix" mapping of the projector: model, 3 x 4 matrix and fit.
void WriteProjectorMatrix(YAML::Emitter& out, const ProjectorMatrixFit& m) {
  out << YAML::Key << "matrix" << YAML::Value << YAML::BeginMap;
  Intrinsics(out, m.model.intrinsics());
  Pose(out, m.model.pose());
  Eigen::Matrix<double, 12, 1> p;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) p(4 * i + j) = m.matrix(i, j);
  Vec(out, "matrix", p);  // row-major 3 x 4, slide units
  out << YAML::Key << "fit" << YAML::Value << YAML::Flow << YAML::BeginMap;
  KeyValue(out, "points_used", m.report.points_used);
  KeyValue(out, "points_dropped", m.report.points_dropped);
  KeyValue(out, "rms_d", m.report.rms_d);
  KeyValue(out, "max_d", m.report.max_d);
  KeyValue(out, "residual_sigma_d", m.report.residual_sigma_d);
  KeyValue(out, "iterations", m.report.iterations);
  KeyValue(out, "converged", m.report.converged);
  out << YAML::EndMap;
  out << YAML::EndMap;
}

// Writes the "projector" mapping: both plane models, the matrix when fitted,
// and the pose.
void WriteProjector(YAML::Emitter& out, const SideCalibration& c) {
  out << YAML::Key << "projector" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "parallel_plane" << YAML::Value << YAML::BeginMap;
  Vec(out, "normal", c.parallel.model.normal);
  KeyValue(out, "spacing_mm", c.parallel.model.spacing_mm);
  KeyValue(out, "e0", c.parallel.model.e0);
  StripeReport(out, c.parallel.report);
  out << YAML::EndMap;
  const PerspectivePlaneModel& pm = c.perspective.model;
  out << YAML::Key << "perspective_plane" << YAML::Value << YAML::BeginMap;
  Vec(out, "n0", pm.n0);
  Vec(out, "p", pm.p);
  Vec(out, "centre_mm", pm.centre_mm);
  Vec(out, "axis_direction", pm.axis_direction);
  KeyValue(out, "gauge_axis", pm.gauge_axis);
  KeyValue(out, "centre_axis", pm.centre_axis);
  KeyValue(out, "centre_to_origin_mm", c.perspective.centre_to_origin_mm);
  KeyValue(out, "axis_to_origin_mm", c.perspective.axis_to_origin_mm);
  StripeReport(out, c.perspective.report);
  out << YAML::EndMap;
  if (c.projector_matrix) WriteProjectorMatrix(out, *c.projector_matrix);
  const ProjectorPose& pp = c.projector;
  out << YAML::Key << "pose" << YAML::Value << YAML::BeginMap;
  Vec(out, "plane_centre_mm", pp.plane_centre_mm);
  Vec(out, "plane_axis", pp.plane_axis);
  KeyValue(out, "plane_centre_distance_mm", pp.plane_centre_distance_mm);
  if (pp.matrix_centre_mm) Vec(out, "matrix_centre_mm", *pp.matrix_centre_mm);
  if (pp.optical_axis) Vec(out, "optical_axis", *pp.optical_axis);
  if (pp.matrix_centre_distance_mm)
    KeyValue(out, "matrix_centre_distance_mm", *pp.matrix_centre_distance_mm);
  if (pp.camera_projector_angle_deg)
    KeyValue(out, "camera_projector_angle_deg", *pp.camera_projector_angle_deg);
  out << YAML::EndMap;
  out << YAML::EndMap;
}

// Writes the "reference" mapping: the ray when fitted and each cross.
void WriteReference(YAML::Emitter& out, const SideCalibration& c) {
  out << YAML::Key << "reference" << YAML::Value << YAML::BeginMap;
  if (c.reference_ray) {
    out << YAML::Key << "ray" << YAML::Value << YAML::Flow << YAML::BeginMap;
    Vec(out, "point_mm", c.reference_ray->point_mm);
    Vec(out, "direction", c.reference_ray->direction);
    out << YAML::EndMap;
  }
  out << YAML::Key << "crosses" << YAML::Value << YAML::BeginSeq;
  for (const ReferenceViewReport& v : c.reference_views) {
    out << YAML::Flow << YAML::BeginMap;
    KeyValue(out, "image", v.image.string());
    KeyValue(out, "z_mm", v.z_mm);
    Vec(out, "centre_px", v.centre_px);
    Vec(out, "world_mm", v.world_mm);
    KeyValue(out, "ray_residual_mm", v.ray_residual_mm);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
}

// Writes the "screens" list, one flow mapping per used screen view.
void WriteScreens(YAML::Emitter& out, const SideCalibration& c) {
  out << YAML::Key << "screens" << YAML::Value << YAML::BeginSeq;
  for (const ScreenViewReport& v : c.screen_views) {
    out << YAML::Flow << YAML::BeginMap;
    KeyValue(out, "image", v.image.string());
    KeyValue(out, "z_mm", v.z_mm);
    KeyValue(out, "lines", v.lines);
    KeyValue(out, "stripe_points", v.stripe_points);
    KeyValue(out, "junctions", v.junctions);
    KeyValue(out, "plane_rms_mm", v.plane_rms_mm);
    if (v.q_offset) KeyValue(out, "q_offset", *v.q_offset);
    KeyValue(out, "matrix_junctions", v.matrix_junctions);
    if (v.matrix_rms_d) KeyValue(out, "matrix_rms_d", *v.matrix_rms_d);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

// Writes the "dropped_views" list; nothing when no view was dropped.
void WriteDroppedViews(YAML::Emitter& out, const SideCalibration& c) {
  if (c.dropped_views.empty()) return;
  out << YAML::Key << "dropped_views" << YAML::Value << YAML::BeginSeq;
  for (const DroppedView& v : c.dropped_views) {
    out << YAML::Flow << YAML::BeginMap;
    KeyValue(out, "image", v.image.string());
    KeyValue(out, "kind", std::string(ToString(v.kind)));
    KeyValue(out, "index", v.index);
    KeyValue(out, "z_mm", v.z_mm);
    KeyValue(out, "reason", v.reason);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

// ---------------------------------------------------------------- reading, by section

// The root mapping, its head (format, version, side) checked as
// calibration_header.h reads it; the record's versions and side filled in.
YAML::Node ReadRoot(const std::string& text, const std::string& name, CalibrationRecord* record) {
  YAML::Node root = ParseCalibrationYaml(text, name);
  const CalibrationHeader header = ReadCalibrationHeader(root, name);
  record->format_version = header.format_version;
  record->software_version = header.software_version;
  record->calibration.side = header.side;
  return root;
}

// Reads image size, manifest hash, pattern and target, each checked.
void ReadHeader(const Reader& r, const YAML::Node& root, SideCalibration& c) {
  const YAML::Node image = r.Child(root, "image", "");
  c.width = r.Get<int>(image, "width", "image");
  c.height = r.Get<int>(image, "height", "image");
  if (c.width < 1 || c.height < 1) r.Fail("image", "width and height must be positive");
  c.manifest_sha256 = r.Get<std::string>(root, "manifest_sha256", "");
  const YAML::Node pat = r.Child(root, "pattern", "");
  c.pattern.lines = r.Get<int>(pat, "lines", "pattern");
  c.pattern.rows = r.Get<int>(pat, "rows", "pattern");
  c.pattern.stroke_width = r.Get<double>(pat, "stroke_width", "pattern");
  std::string why;
  if (!c.pattern.IsValid(&why)) r.Fail("pattern", why);
  const YAML::Node target = r.Child(root, "target", "");
  c.target.rows = r.Get<int>(target, "rows", "target");
  c.target.cols = r.Get<int>(target, "cols", "target");
  c.target.pitch_mm = r.Get<double>(target, "pitch_mm", "target");
  c.target.square_mm = r.Get<double>(target, "square_mm", "target");
  if (!c.target.IsValid(&why)) r.Fail("target", why);
}

// Reads camera.report.sigmas, the parameter standard deviations.
CameraParameterSigmas ReadCameraSigmas(const Reader& r, const YAML::Node& rep,
                                       const std::string& rw) {
  const std::string sw = rw + ".sigmas";
  const YAML::Node s = r.Child(rep, "sigmas", rw);
  CameraParameterSigmas sig;
  sig.f_px = r.Get<double>(s, "f_px", sw);
  sig.sx = r.Get<double>(s, "sx", sw);
  sig.fx_px = r.Get<double>(s, "fx_px", sw);
  sig.fy_px = r.Get<double>(s, "fy_px", sw);
  sig.cx_px = r.Get<double>(s, "cx_px", sw);
  sig.cy_px = r.Get<double>(s, "cy_px", sw);
  sig.k1 = r.Get<double>(s, "k1", sw);
  sig.k2 = r.Get<double>(s, "k2", sw);
  sig.rotation_rad = r.Vector3(s, "rotation_rad", sw);
  sig.translation_mm = r.Vector3(s, "translation_mm", sw);
  return sig;
}

// Reads camera.report (without its per-view residuals).
void ReadCameraReport(const Reader& r, const YAML::Node& camera, CameraCalibrationReport& cr) {
  const YAML::Node rep = r.Child(camera, "report", "camera");
  const std::string rw = "camera.report";
  cr.num_points = r.Get<int>(rep, "points", rw);
  cr.num_views = r.Get<int>(rep, "views", rw);
  cr.rms_px = r.Get<double>(rep, "rms_px", rw);
  cr.max_px = r.Get<double>(rep, "max_px", rw);
  cr.rms_mm = r.Get<double>(rep, "rms_mm", rw);
  cr.max_mm = r.Get<double>(rep, "max_mm", rw);
  cr.residual_sigma_px = r.Get<double>(rep, "residual_sigma_px", rw);
  cr.f_px = r.Get<double>(rep, "f_px", rw);
  cr.sx = r.Get<double>(rep, "sx", rw);
  const auto init = r.Get<std::string>(rep, "initialisation", rw);
  if (init != "tsai" && init != "dlt") r.Fail(rw + ".initialisation", "must be tsai or dlt");
  cr.initialisation = init == "tsai" ? CameraInitialisation::kTsai : CameraInitialisation::kDlt;
  cr.iterations = r.Get<int>(rep, "iterations", rw);
  cr.converged = r.Get<bool>(rep, "converged", rw);
  if (rep["sigmas"]) cr.sigmas = ReadCameraSigmas(r, rep, rw);
}

// Reads the "camera" mapping: model, report, and the views, whose residuals
// also fill the report's per-view lists.
void ReadCamera(const Reader& r, const YAML::Node& root, SideCalibration& c) {
  const YAML::Node camera = r.Child(root, "camera", "");
  c.camera.model =
      geometry::PinholeModel(ReadIntrinsics(r, camera, "camera"), ReadPose(r, camera, "camera"));
  CameraCalibrationReport& cr = c.camera.report;
  ReadCameraReport(r, camera, cr);
  const YAML::Node views = r.Child(camera, "views", "camera", false);
  if (!views.IsSequence()) r.Fail("camera.views", "must be a list");
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string w = "camera.views[" + std::to_string(i) + "]";
    CameraViewReport v;
    v.image = r.Get<std::string>(views[i], "image", w);
    v.z_mm = r.Get<double>(views[i], "z_mm", w);
    v.rms_px = r.Get<double>(views[i], "rms_px", w);
    v.rms_mm = r.Get<double>(views[i], "rms_mm", w);
    v.max_grid_residual = r.Get<double>(views[i], "max_grid_residual", w);
    cr.view_rms_px.push_back(v.rms_px);
    cr.view_rms_mm.push_back(v.rms_mm);
    c.camera_views.push_back(std::move(v));
  }
}

// Reads projector.parallel_plane and projector.perspective_plane.
void ReadPlaneModels(const Reader& r, const YAML::Node& projector, SideCalibration& c) {
  {
    const std::string w = "projector.parallel_plane";
    const YAML::Node n = r.Child(projector, "parallel_plane", "projector");
    c.parallel.model.normal = Unit(r, r.Vector3(n, "normal", w), w + ".normal");
    c.parallel.model.spacing_mm = r.Get<double>(n, "spacing_mm", w);
    if (!(c.parallel.model.spacing_mm > 0.0)) r.Fail(w + ".spacing_mm", "must be positive");
    c.parallel.model.e0 = r.Get<double>(n, "e0", w);
    c.parallel.report = ReadStripeReport(r, n, w);
  }
  {
    const std::string w = "projector.perspective_plane";
    const YAML::Node n = r.Child(projector, "perspective_plane", "projector");
    PerspectivePlaneModel& m = c.perspective.model;
    m.n0 = r.Vector3(n, "n0", w);
    m.p = r.Vector3(n, "p", w);
    m.centre_mm = r.Vector3(n, "centre_mm", w);
    m.axis_direction = Unit(r, r.Vector3(n, "axis_direction", w), w + ".axis_direction");
    m.gauge_axis = r.Get<int>(n, "gauge_axis", w);
    m.centre_axis = r.Get<int>(n, "centre_axis", w);
    if (m.gauge_axis < 0 || m.gauge_axis > 2 || m.centre_axis < 0 || m.centre_axis > 2)
      r.Fail(w, "gauge_axis and centre_axis must be 0, 1 or 2");
    c.perspective.centre_to_origin_mm = r.Get<double>(n, "centre_to_origin_mm", w);
    c.perspective.axis_to_origin_mm = r.Get<double>(n, "axis_to_origin_mm", w);
    c.perspective.report = ReadStripeReport(r, n, w);
  }
}

// Reads projector.matrix: model, 3 x 4 matrix and fit.
ProjectorMatrixFit ReadProjectorMatrix(const Reader& r, const YAML::Node& projector) {
  const std::string w = "projector.matrix";
  const YAML::Node n = r.Child(projector, "matrix", "projector");
  ProjectorMatrixFit m;
  m.model = geometry::PinholeModel(ReadIntrinsics(r, n, w), ReadPose(r, n, w));
  const Eigen::VectorXd p = r.Vector(n, "matrix", w, 12);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) m.matrix(i, j) = p(4 * i + j);
  const std::string fw = w + ".fit";
  const YAML::Node f = r.Child(n, "fit", w);
  m.report.points_used = r.Get<int>(f, "points_used", fw);
  m.report.points_dropped = r.Get<int>(f, "points_dropped", fw);
  m.report.rms_d = r.Get<double>(f, "rms_d", fw);
  m.report.max_d = r.Get<double>(f, "max_d", fw);
  m.report.residual_sigma_d = r.Get<double>(f, "residual_sigma_d", fw);
  m.report.iterations = r.Get<int>(f, "iterations", fw);
  m.report.converged = r.Get<bool>(f, "converged", fw);
  return m;
}

// Reads projector.pose; its matrix-derived keys are optional.
void ReadProjectorPose(const Reader& r, const YAML::Node& projector, ProjectorPose& pp) {
  const std::string w = "projector.pose";
  const YAML::Node n = r.Child(projector, "pose", "projector");
  pp.plane_centre_mm = r.Vector3(n, "plane_centre_mm", w);
  pp.plane_axis = r.Vector3(n, "plane_axis", w);
  pp.plane_centre_distance_mm = r.Get<double>(n, "plane_centre_distance_mm", w);
  if (n["matrix_centre_mm"]) pp.matrix_centre_mm = r.Vector3(n, "matrix_centre_mm", w);
  if (n["optical_axis"]) pp.optical_axis = r.Vector3(n, "optical_axis", w);
  if (n["matrix_centre_distance_mm"])
    pp.matrix_centre_distance_mm = r.Get<double>(n, "matrix_centre_distance_mm", w);
  if (n["camera_projector_angle_deg"])
    pp.camera_projector_angle_deg = r.Get<double>(n, "camera_projector_angle_deg", w);
}

// Reads the "reference" mapping: the ray when present and each cross.
void ReadReference(const Reader& r, const YAML::Node& root, SideCalibration& c) {
  const YAML::Node reference = r.Child(root, "reference", "");
  if (reference["ray"]) {
    const YAML::Node n = r.Child(reference, "ray", "reference");
    ReferenceRay ray;
    ray.point_mm = r.Vector3(n, "point_mm", "reference.ray");
    ray.direction = Unit(r, r.Vector3(n, "direction", "reference.ray"), "reference.ray.direction");
    c.reference_ray = ray;
  }
  const YAML::Node crosses = r.Child(reference, "crosses", "reference", false);
  if (!crosses.IsSequence()) r.Fail("reference.crosses", "must be a list");
  for (size_t i = 0; i < crosses.size(); ++i) {
    const std::string w = "reference.crosses[" + std::to_string(i) + "]";
    ReferenceViewReport v;
    v.image = r.Get<std::string>(crosses[i], "image", w);
    v.z_mm = r.Get<double>(crosses[i], "z_mm", w);
    v.centre_px = r.Vector(crosses[i], "centre_px", w, 2);
    v.world_mm = r.Vector3(crosses[i], "world_mm", w);
    v.ray_residual_mm = r.Get<double>(crosses[i], "ray_residual_mm", w);
    c.reference_views.push_back(std::move(v));
  }
}

// Reads the "screens" list; a q_offset, when present, must be even.
void ReadScreens(const Reader& r, const YAML::Node& root, SideCalibration& c) {
  const YAML::Node screens = r.Child(root, "screens", "", false);
  if (!screens.IsSequence()) r.Fail("screens", "must be a list");
  for (size_t i = 0; i < screens.size(); ++i) {
    const std::string w = "screens[" + std::to_string(i) + "]";
    ScreenViewReport v;
    v.image = r.Get<std::string>(screens[i], "image", w);
    v.z_mm = r.Get<double>(screens[i], "z_mm", w);
    v.lines = r.Get<int>(screens[i], "lines", w);
    v.stripe_points = r.Get<int>(screens[i], "stripe_points", w);
    v.junctions = r.Get<int>(screens[i], "junctions", w);
    v.plane_rms_mm = r.Get<double>(screens[i], "plane_rms_mm", w);
    if (screens[i]["q_offset"]) {
      v.q_offset = r.Get<int>(screens[i], "q_offset", w);
      if (*v.q_offset % 2 != 0) r.Fail(w + ".q_offset", "must be even");
    }
    v.matrix_junctions = r.Get<int>(screens[i], "matrix_junctions", w);
    if (screens[i]["matrix_rms_d"]) v.matrix_rms_d = r.Get<double>(screens[i], "matrix_rms_d", w);
    c.screen_views.push_back(std::move(v));
  }
}

// Reads the optional "dropped_views" list.
void ReadDroppedViews(const Reader& r, const YAML::Node& root, SideCalibration& c) {
  if (!root["dropped_views"]) return;
  const YAML::Node dropped = r.Child(root, "dropped_views", "", false);
  if (!dropped.IsSequence()) r.Fail("dropped_views", "must be a list");
  for (size_t i = 0; i < dropped.size(); ++i) {
    const std::string w = "dropped_views[" + std::to_string(i) + "]";
    DroppedView v;
    v.image = r.Get<std::string>(dropped[i], "image", w);
    const std::string kind = r.Get<std::string>(dropped[i], "kind", w);
    if (kind == ToString(ViewKind::kCamera)) {
      v.kind = ViewKind::kCamera;
    } else if (kind == ToString(ViewKind::kScreen)) {
      v.kind = ViewKind::kScreen;
    } else if (kind == ToString(ViewKind::kReference)) {
      v.kind = ViewKind::kReference;
    } else {
      r.Fail(w + ".kind", "must be camera, screen or reference, not \"" + kind + "\"");
    }
    v.index = r.Get<int>(dropped[i], "index", w);
    if (v.index < 0) r.Fail(w + ".index", "must not be negative");
    v.z_mm = r.Get<double>(dropped[i], "z_mm", w);
    v.reason = r.Get<std::string>(dropped[i], "reason", w);
    c.dropped_views.push_back(std::move(v));
  }
}

}  // namespace

std::string CalibrationToYaml(const SideCalibration& c, const std::string& software_version) {
  YAML::Emitter out;
  out << YAML::Comment(
      "BSLS calibration of one side (thesis chapter 6). World mm (contracts section 3), camera "
      "pixels, projector slide pitches d; rotations row-major, world -> device.");
  out << YAML::BeginMap;
  WriteHeader(out, c, software_version);
  // Camera (thesis 6.1).
  WriteCamera(out, c);
  // Projector (thesis 6.2).
  WriteProjector(out, c);
  // Slide rows (reference crosses) and the screens.
  WriteReference(out, c);
  WriteScreens(out, c);
  // Listed views left out, so the file says what it was made from.
  WriteDroppedViews(out, c);

  out << YAML::Key << "uncertainty" << YAML::Value << YAML::BeginMap;
  KeyValue(out, "stripe_centre_px", c.sigmas.stripe_centre_px);
  KeyValue(out, "target_point_px", c.sigmas.target_point_px);
  KeyValue(out, "plane_mm", c.sigmas.plane_mm);
  out << YAML::EndMap;
  out << YAML::EndMap;
  if (!out.good()) throw std::logic_error("calibration YAML: " + out.GetLastError());
  return std::string(out.c_str()) + "\n";
}

CalibrationRecord CalibrationFromYaml(const std::string& text, const std::string& name) {
  const Reader r(name);
  CalibrationRecord record;
  const YAML::Node root = ReadRoot(text, name, &record);
  SideCalibration& c = record.calibration;
  ReadHeader(r, root, c);

  // Camera.
  ReadCamera(r, root, c);

  // Projector.
  const YAML::Node projector = r.Child(root, "projector", "");
  ReadPlaneModels(r, projector, c);
  if (projector["matrix"]) c.projector_matrix = ReadProjectorMatrix(r, projector);
  ReadProjectorPose(r, projector, c.projector);

  // Reference crosses and screens.
  ReadReference(r, root, c);
  ReadScreens(r, root, c);
  ReadDroppedViews(r, root, c);

  const YAML::Node u = r.Child(root, "uncertainty", "");
  c.sigmas.stripe_centre_px = r.Get<double>(u, "stripe_centre_px", "uncertainty");
  c.sigmas.target_point_px = r.Get<double>(u, "target_point_px", "uncertainty");
  c.sigmas.plane_mm = r.Get<double>(u, "plane_mm", "uncertainty");
  if (c.sigmas.stripe_centre_px < 0.0 || c.sigmas.target_point_px < 0.0 || c.sigmas.plane_mm < 0.0)
    r.Fail("uncertainty", "sigmas must not be negative");
  return record;
}

void SaveCalibration(const std::filesystem::path& path, const SideCalibration& calibration,
                     const std::string& software_version) {
  WriteFileAtomically(path.string(), CalibrationToYaml(calibration, software_version));
}

CalibrationRecord LoadCalibration(const std::filesystem::path& path) {
  return CalibrationFromYaml(ReadCalibrationText(path), path.string());
}

}  // namespace bsls::calibration
