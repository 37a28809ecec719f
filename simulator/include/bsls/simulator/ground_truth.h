// Exact ground truth of a simulated image, computed from the geometry (never
// from the rendered image): where each slide junction and each vertical line
// lands in the image, and per-pixel maps of what the camera sees.
//
// Frames and units: image pixels with the origin at the centre of the top-left
// pixel (contracts section 5), world millimetres (contracts section 3), slide
// and pattern coordinates in line pitches d (bsls/pattern/brick_pattern.h).
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_SIMULATOR_GROUND_TRUTH_H_
#define BSLS_SIMULATOR_GROUND_TRUTH_H_

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "bsls/geometry/pinhole_model.h"
#include "bsls/pattern/brick_pattern.h"
#include "bsls/simulator/scene.h"

namespace bsls::simulator {

// Thresholds of the ground-truth computation.
struct TruthParams {
  // Horizontally adjacent pixels whose camera distances differ by more than
  // this (mm) are on different surfaces: no line crossing between them, and
  // both are boundary pixels.
  double max_depth_step_mm = 5.0;
  // ... likewise when their pattern u differs by more than this (d).
  double max_u_step = 0.5;
  // A junction is visible when the camera ray through its image point first
  // hits a point within this distance (mm) of the junction's world point.
  double visibility_tolerance_mm = 1e-3;
  // Boundary distances are searched up to this radius (px) and capped there.
  double boundary_search_px = 32.0;

  // True when every threshold is positive and finite; otherwise names it.
  bool IsValid(std::string* error) const;
};

// One slide junction (contracts section 1) where it lands.
struct TruthJunction {
  int p = 0;  // vertical line
  int v = 0;  // slide row (absolute; decoders report q = v up to an even offset)
  pattern::JunctionKind kind = pattern::JunctionKind::kDirect;
  Eigen::Vector2d image = Eigen::Vector2d::Zero();  // distorted image point, px
  Eigen::Vector3d world = Eigen::Vector3d::Zero();  // first surface point on the projector ray, mm
  bool in_image = false;  // image point inside [-0.5, width-0.5] x [-0.5, height-0.5]
  // in_image, but an image edge runs through its segment's or its line's
  // stroke lengthwise (the stroke's half width w/2 reaches beyond the edge):
  // the camera sees part of a stroke only, so the junction is not counted as
  // visible (docs/decoding.md, "Ground truth at the image edge").
  bool cut_by_edge = false;
  // in_image, not cut_by_edge, and the camera sees exactly this lit side of world.
  bool visible = false;
  // Distance (px) from the image point to the nearest boundary pixel: a seen
  // and lit pixel next to an unlit/unseen one or across a depth or u jump
  // (projector shadow, camera occlusion, silhouette); the image edge is not a
  // boundary. Capped at TruthParams::boundary_search_px; 0 when not in_image.
  double boundary_distance_px = 0.0;
  double albedo = 0.0;         // at world
  double cos_incidence = 0.0;  // surface normal . direction to the projector
  double cos_view = 0.0;       // surface normal . direction to the camera (< 0: seen from behind)
};

// The centre line of vertical line p: the image points where the visible, lit
// surface has pattern coordinate u = p, one per crossing of an image row,
// ordered by y then x. A row normally holds one point; it holds several only
// where the line really crosses the row several times (strongly curved or
// occluding surfaces) — every crossing is kept so that an evaluation can match
// a decoded point to the nearest one.
struct TruthLine {
  int p = 0;
  std::vector<Eigen::Vector2d> points;  // (x, y) px; y is an integer row
};

// Per-pixel maps at pixel centres (width x height, row-major like the image).
struct PixelMaps {
  cv::Mat u;       // CV_64FC1 pattern u (d) of the lit surface point; NaN where not lit
  cv::Mat v;       // CV_64FC1 pattern v (d); NaN where not lit
  cv::Mat depth;   // CV_64FC1 distance from the camera centre along the ray (mm); NaN: no hit
  cv::Mat height;  // CV_64FC1 world z of the surface point (mm); NaN: no hit
  cv::Mat hit;     // CV_8UC1 255 where the camera ray hits a surface
  cv::Mat lit;     // CV_8UC1 255 where that point is lit by the projector
};

// Everything known exactly about one simulated image.
struct GroundTruth {
  pattern::Side side = pattern::Side::kLeft;
  pattern::Slide slide = pattern::Slide::kLeftBrick;
  pattern::PatternSpec pattern;
  int width = 0;
  int height = 0;
  geometry::PinholeModel camera;     // pixels
  geometry::PinholeModel projector;  // slide units d
  // Every brick junction whose projector ray hits a surface, visible or not,
  // ordered by p then v. Empty for the reference cross (slide 1).
  std::vector<TruthJunction> junctions;
  // Lines with at least one point, by increasing p. For slide 1: line 0 only.
  std::vector<TruthLine> lines;
  PixelMaps maps;
};

// Traces one camera ray per pixel centre. Thread-safe; uses cv::parallel_for_.
PixelMaps TracePixelMaps(const Scene& scene);

// Junctions and lines of `scene` from its geometry and its pixel maps
// (`maps` must come from TracePixelMaps(scene)). Throws std::invalid_argument
// when the scene or params are invalid.
GroundTruth ComputeGroundTruth(const Scene& scene, const PixelMaps& maps,
                               const TruthParams& params = {});
// The same, tracing the maps first.
GroundTruth ComputeGroundTruth(const Scene& scene, const TruthParams& params = {});

// Contracts section 5 layout with truth fields:
// {"side", "slide", "width", "height", "pattern": {"lines", "rows", "stroke_width"},
//  "camera"/"projector": {"fx", "fy", "cx", "cy", "k1", "k2",
//                         "rotation": [9, row-major, world->device], "translation": [3]},
//  "junctions": [{"x", "y", "p", "v", "kind", "world": [x, y, z],
//                 "boundary_distance_px", "albedo", "cos_incidence", "cos_view"}],
//  "hidden_junctions": [same, plus "in_image", "cut_by_edge"],
//  "lines": [{"p", "points": [[x, y], ...]}]}
// "junctions" holds the visible ones only. Pixel maps are not included.
nlohmann::json ToJson(const GroundTruth& truth);

// A camera or projector as the truth files write it: fx, fy, cx, cy, k1, k2,
// the world-to-device rotation (row-major) and translation.
nlohmann::json DeviceJson(const geometry::PinholeModel& model);

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_GROUND_TRUTH_H_
