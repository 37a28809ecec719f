#include "bsls/simulator/ground_truth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <optional>
#include <stdexcept>

namespace bsls::simulator {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json JunctionJson(const TruthJunction& j, bool with_in_image) {
  nlohmann::json out = {{"x", j.image.x()},
                        {"y", j.image.y()},
                        {"p", j.p},
                        {"v", j.v},
                        {"kind", std::string(pattern::ToString(j.kind))},
                        {"world", {j.world.x(), j.world.y(), j.world.z()}},
                        {"boundary_distance_px", j.boundary_distance_px},
                        {"albedo", j.albedo},
                        {"cos_incidence", j.cos_incidence},
                        {"cos_view", j.cos_view}};
  if (with_in_image) {
    out["in_image"] = j.in_image;
    out["cut_by_edge"] = j.cut_by_edge;
  }
  return out;
}

// 255 where a lit pixel touches (4-neighbourhood) an unlit one or a depth/u jump.
cv::Mat BoundaryMask(const PixelMaps& maps, const TruthParams& params) {
  const int width = maps.lit.cols;
  const int height = maps.lit.rows;
  cv::Mat boundary(height, width, CV_8UC1, cv::Scalar(0));
  auto lit = [&](int x, int y) { return maps.lit.at<uchar>(y, x) != 0; };
  auto jump = [&](int x0, int y0, int x1, int y1) {
    return std::abs(maps.depth.at<double>(y0, x0) - maps.depth.at<double>(y1, x1)) >
               params.max_depth_step_mm ||
           std::abs(maps.u.at<double>(y0, x0) - maps.u.at<double>(y1, x1)) > params.max_u_step;
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!lit(x, y)) continue;
      constexpr int kDx[4] = {1, -1, 0, 0};
      constexpr int kDy[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int nx = x + kDx[k];
        const int ny = y + kDy[k];
        if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;  // image edge: no boundary
        if (!lit(nx, ny) || jump(x, y, nx, ny)) {
          boundary.at<uchar>(y, x) = 255;
          break;
        }
      }
    }
  }
  return boundary;
}

double BoundaryDistance(const cv::Mat& boundary, const Eigen::Vector2d& image, double radius) {
  const int x0 = std::max(0, static_cast<int>(std::floor(image.x() - radius)));
  const int x1 = std::min(boundary.cols - 1, static_cast<int>(std::ceil(image.x() + radius)));
  const int y0 = std::max(0, static_cast<int>(std::floor(image.y() - radius)));
  const int y1 = std::min(boundary.rows - 1, static_cast<int>(std::ceil(image.y() + radius)));
  double best = radius;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (boundary.at<uchar>(y, x)) best = std::min(best, std::hypot(x - image.x(), y - image.y()));
  return best;
}

// The image point of slide point `st` on the tangent plane (point, normal)
// of the surface: near a junction, the strokes' edges land there.
std::optional<Eigen::Vector2d> OnTangentPlane(const Scene& scene, const Eigen::Vector2d& st,
                                              const Eigen::Vector3d& point,
                                              const Eigen::Vector3d& normal) {
  const geometry::Ray ray = scene.projector.BackProject(st);
  const double den = normal.dot(ray.direction);
  if (std::abs(den) < 1e-12) return std::nullopt;
  return scene.camera.Project(ray.At(normal.dot(point - ray.origin) / den));
}

// True when an image edge runs through a stroke of the junction lengthwise:
// its segment's stroke (rows v -+ w/2) reaches beyond the top or bottom edge,
// or its line's stroke (u = p -+ w/2) beyond the left or right edge. The
// camera then sees only part of that stroke's width: no centre to measure
// and no T to tell from a line's end (docs/decoding.md, "Ground truth at
// the image edge").
bool CutByImageEdge(const Scene& scene, const pattern::SlideJunction& sj,
                    const Eigen::Vector3d& world, const Eigen::Vector3d& normal) {
  const double half = scene.pattern.stroke_width / 2.0;
  const double s = pattern::SFromU(scene.side, sj.p);
  const double lo_x = -0.5, hi_x = scene.width - 0.5, lo_y = -0.5, hi_y = scene.height - 0.5;
  for (double k : {-1.0, 1.0}) {
    const auto across_segment =
        OnTangentPlane(scene, Eigen::Vector2d(s, sj.v + k * half), world, normal);
    if (!across_segment || across_segment->y() < lo_y || across_segment->y() > hi_y) return true;
    const auto across_line =
        OnTangentPlane(scene, Eigen::Vector2d(s + k * half, sj.v), world, normal);
    if (!across_line || across_line->x() < lo_x || across_line->x() > hi_x) return true;
  }
  return false;
}

std::vector<TruthJunction> TraceJunctions(const Scene& scene, const cv::Mat& boundary,
                                          const TruthParams& params) {
  std::vector<TruthJunction> out;
  if (scene.slide == pattern::Slide::kReferenceCross) return out;
  const Eigen::Vector3d camera_centre = scene.camera.Centre();
  for (const pattern::SlideJunction& sj : pattern::AllJunctions(scene.pattern)) {
    const Eigen::Vector2d st(pattern::SFromU(scene.side, sj.p), sj.v);
    const geometry::Ray ray = scene.projector.BackProject(st);
    const auto hit = scene.Intersect(ray, std::numeric_limits<double>::infinity());
    if (!hit) continue;
    TruthJunction j;
    j.p = sj.p;
    j.v = sj.v;
    j.kind = sj.kind;
    j.world = hit->point;
    j.albedo = scene.albedo.At(j.world);
    // Normals on the side the projector lights.
    Eigen::Vector3d normal = hit->normal;
    Eigen::Vector3d facet = hit->geometric_normal;
    if (facet.dot(ray.direction) > 0.0) {
      normal = -normal;
      facet = -facet;
    }
    j.cos_incidence = -normal.dot(ray.direction);
    const Eigen::Vector3d to_camera = (camera_centre - j.world).normalized();
    j.cos_view = normal.dot(to_camera);
    const auto image = scene.camera.Project(j.world);
    if (image) {
      j.image = *image;
      j.in_image = j.image.x() >= -0.5 && j.image.x() <= scene.width - 0.5 && j.image.y() >= -0.5 &&
                   j.image.y() <= scene.height - 0.5;
    }
    if (j.in_image) j.cut_by_edge = CutByImageEdge(scene, sj, j.world, facet);
    if (j.in_image && !j.cut_by_edge && facet.dot(to_camera) > 0.0) {
      const geometry::Ray back = scene.camera.BackProject(j.image);
      const auto seen = scene.Intersect(back, std::numeric_limits<double>::infinity());
      j.visible = seen && (seen->point - j.world).norm() <= params.visibility_tolerance_mm;
    }
    if (j.in_image)
      j.boundary_distance_px = BoundaryDistance(boundary, j.image, params.boundary_search_px);
    out.push_back(j);
  }
  return out;
}

std::vector<TruthLine> TraceLines(const Scene& scene, const PixelMaps& maps,
                                  const TruthParams& params) {
  const int lines = scene.slide == pattern::Slide::kReferenceCross ? 1 : scene.pattern.lines;
  const double v_max = scene.pattern.rows + scene.pattern.stroke_width / 2.0;
  std::vector<TruthLine> out(lines);
  for (int p = 0; p < lines; ++p) out[p].p = p;
  for (int y = 0; y < maps.u.rows; ++y) {
    const double* u = maps.u.ptr<double>(y);
    const double* v = maps.v.ptr<double>(y);
    const double* depth = maps.depth.ptr<double>(y);
    const uchar* lit = maps.lit.ptr<uchar>(y);
    for (int x = 0; x + 1 < maps.u.cols; ++x) {
      if (!lit[x] || !lit[x + 1]) continue;
      if (std::abs(depth[x] - depth[x + 1]) > params.max_depth_step_mm) continue;
      if (std::abs(u[x] - u[x + 1]) > params.max_u_step) continue;
      // Line p crosses between the pixels when min(u) < p <= max(u).
      const int p_first = static_cast<int>(std::floor(std::min(u[x], u[x + 1]))) + 1;
      const int p_last = static_cast<int>(std::floor(std::max(u[x], u[x + 1])));
      for (int p = std::max(p_first, 0); p <= std::min(p_last, lines - 1); ++p) {
        const double a = u[x] - p;
        const double b = u[x + 1] - p;
        const double frac = a / (a - b);
        const double v_at = v[x] + frac * (v[x + 1] - v[x]);
        if (std::abs(v_at) > v_max) continue;
        out[p].points.emplace_back(x + frac, y);
      }
    }
  }
  std::erase_if(out, [](const TruthLine& line) { return line.points.empty(); });
  return out;
}

}  // namespace

nlohmann::json DeviceJson(const geometry::PinholeModel& model) {
  const geometry::Intrinsics& in = model.intrinsics();
  const geometry::Pose& pose = model.pose();
  nlohmann::json rotation = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rotation.push_back(pose.rotation(r, c));
  return {{"fx", in.fx},
          {"fy", in.fy},
          {"cx", in.cx},
          {"cy", in.cy},
          {"k1", in.k1},
          {"k2", in.k2},
          {"rotation", rotation},
          {"translation", {pose.translation.x(), pose.translation.y(), pose.translation.z()}}};
}

bool TruthParams::IsValid(std::string* error) const {
  auto ok = [](double value) { return value > 0.0 && std::isfinite(value); };
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!ok(max_depth_step_mm)) return fail("truth max_depth_step_mm must be positive and finite");
  if (!ok(max_u_step)) return fail("truth max_u_step must be positive and finite");
  if (!ok(visibility_tolerance_mm))
    return fail("truth visibility_tolerance_mm must be positive and finite");
  if (!ok(boundary_search_px)) return fail("truth boundary_search_px must be positive and finite");
  return true;
}

PixelMaps TracePixelMaps(const Scene& scene) {
  PixelMaps maps;
  maps.u.create(scene.height, scene.width, CV_64FC1);
  maps.v.create(scene.height, scene.width, CV_64FC1);
  maps.depth.create(scene.height, scene.width, CV_64FC1);
  maps.height.create(scene.height, scene.width, CV_64FC1);
  maps.hit = cv::Mat(scene.height, scene.width, CV_8UC1, cv::Scalar(0));
  maps.lit = cv::Mat(scene.height, scene.width, CV_8UC1, cv::Scalar(0));
  cv::parallel_for_(cv::Range(0, scene.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      double* u = maps.u.ptr<double>(y);
      double* v = maps.v.ptr<double>(y);
      double* depth = maps.depth.ptr<double>(y);
      double* height = maps.height.ptr<double>(y);
      uchar* hit = maps.hit.ptr<uchar>(y);
      uchar* lit = maps.lit.ptr<uchar>(y);
      for (int x = 0; x < scene.width; ++x) {
        u[x] = v[x] = depth[x] = height[x] = kNaN;
        const auto sample = scene.TraceCameraRay(scene.camera.BackProject(Eigen::Vector2d(x, y)));
        if (!sample) continue;
        hit[x] = 255;
        depth[x] = sample->hit.distance;
        height[x] = sample->hit.point.z();
        if (!sample->lit) continue;
        lit[x] = 255;
        u[x] = pattern::UFromS(scene.side, sample->slide_st.x());
        v[x] = sample->slide_st.y();
      }
    }
  });
  return maps;
}

GroundTruth ComputeGroundTruth(const Scene& scene, const PixelMaps& maps,
                               const TruthParams& params) {
  std::string error;
  if (!scene.IsValid(&error)) throw std::invalid_argument("ComputeGroundTruth: " + error);
  if (!params.IsValid(&error)) throw std::invalid_argument("ComputeGroundTruth: " + error);
  if (maps.u.rows != scene.height || maps.u.cols != scene.width || maps.u.type() != CV_64FC1)
    throw std::invalid_argument("ComputeGroundTruth: pixel maps do not match the scene's image");
  GroundTruth truth;
  truth.side = scene.side;
  truth.slide = scene.slide;
  truth.pattern = scene.pattern;
  truth.width = scene.width;
  truth.height = scene.height;
  truth.camera = scene.camera;
  truth.projector = scene.projector;
  truth.maps = maps;
  const cv::Mat boundary = BoundaryMask(maps, params);
  truth.junctions = TraceJunctions(scene, boundary, params);
  truth.lines = TraceLines(scene, maps, params);
  return truth;
}

GroundTruth ComputeGroundTruth(const Scene& scene, const TruthParams& params) {
  std::string error;
  if (!scene.IsValid(&error)) throw std::invalid_argument("ComputeGroundTruth: " + error);
  return ComputeGroundTruth(scene, TracePixelMaps(scene), params);
}

nlohmann::json ToJson(const GroundTruth& truth) {
  nlohmann::json junctions = nlohmann::json::array();
  nlohmann::json hidden = nlohmann::json::array();
  for (const TruthJunction& j : truth.junctions) {
    if (j.visible)
      junctions.push_back(JunctionJson(j, false));
    else
      hidden.push_back(JunctionJson(j, true));
  }
  nlohmann::json lines = nlohmann::json::array();
  for (const TruthLine& line : truth.lines) {
    nlohmann::json points = nlohmann::json::array();
    for (const Eigen::Vector2d& point : line.points) points.push_back({point.x(), point.y()});
    lines.push_back({{"p", line.p}, {"points", points}});
  }
  return {{"side", std::string(pattern::ToString(truth.side))},
          {"slide", static_cast<int>(truth.slide)},
          {"width", truth.width},
          {"height", truth.height},
          {"pattern",
           {{"lines", truth.pattern.lines},
            {"rows", truth.pattern.rows},
            {"stroke_width", truth.pattern.stroke_width}}},
          {"camera", DeviceJson(truth.camera)},
          {"projector", DeviceJson(truth.projector)},
          {"junctions", junctions},
          {"hidden_junctions", hidden},
          {"lines", lines}};
}

}  // namespace bsls::simulator
