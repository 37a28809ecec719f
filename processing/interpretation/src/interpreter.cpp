#include "bsls/interpretation/interpreter.h"

#include <memory>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "bsls/extraction/pruning.h"
#include "bsls/interpretation/junction_detect.h"

namespace bsls::interpretation {
namespace {

// Thesis 5.2.3.1 stage 8: a junction whose window shows fewer than three
// paths is a degree-2 point with a noisy pixel or two; prune its short spurs.
// Asks `cancel` after the graph and every few hundred nodes.
int PruneFalseJunctions(cv::Mat& sk, pattern::Side side, const InterpretationParams& params,
                        const Cancellation& cancel) {
  const SkeletonGraph g = SkeletonGraph::Build(sk, params.graph, cancel);
  int pruned = 0;
  for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n) {
    if (n % 512 == 0) cancel.ThrowIfRequested("the false junctions");
    const SkeletonNode& node = g.nodes()[n];
    if (node.kind != NodeKind::kJunction) continue;
    const cv::Point c(cvRound(node.centre.x), cvRound(node.centre.y));
    cv::Point candidate = node.pixels.front();
    for (const cv::Point& p : node.pixels)
      if (std::abs(p.x - c.x) + std::abs(p.y - c.y) <
          std::abs(candidate.x - c.x) + std::abs(candidate.y - c.y))
        candidate = p;
    if (DetectJunction(sk, candidate, side, params.junction).is_junction) continue;
    for (int h : node.rotation) {
      const int t = g.Target(h);
      if (g.nodes()[t].kind != NodeKind::kEnd || g.Length(h) > params.junction.min_radius) continue;
      for (const cv::Point& p : g.Pixels(h)) sk.at<uchar>(p) = 0;
      sk.at<uchar>(g.nodes()[t].pixels.front()) = 0;
      ++pruned;
    }
  }
  return pruned;
}

// Moves every point of `r` from the framed skeleton's coordinates into the
// image's (`image` is where the image lies in the frame); pixels that lie in
// the frame (stubs beyond the image's edge) are dropped.
void ToImageFrame(const cv::Rect& image, InterpretationResult* r) {
  const cv::Point o = image.tl();
  const cv::Rect inside(0, 0, image.width, image.height);
  auto move_all = [&](std::vector<cv::Point>& pts) {
    std::vector<cv::Point> kept;
    kept.reserve(pts.size());
    for (const cv::Point& p : pts)
      if (inside.contains(p - o)) kept.push_back(p - o);
    pts = std::move(kept);
  };
  move_all(r->reference.pixels);
  r->reference.overlap -= o;
  for (auto& [from, to] : r->reference.fills) from -= o, to -= o;
  for (Repair& repair : r->repairs) repair.from -= o, repair.to -= o;
  for (cv::Point& c : r->corners) c -= o;
  for (LabelledJunction& j : r->labelling.junctions) {
    j.position -= cv::Point2d(o);
    move_all(j.segment);
  }
  for (LabelledLine& line : r->labelling.lines) move_all(line.pixels);
}

}  // namespace

bool InterpretationParams::IsValid(std::string* error) const {
  if (!graph.IsValid(error) || !junction.IsValid(error) || !corners.IsValid(error) ||
      !reference.IsValid(error) || !repair.IsValid(error) || !labelling.IsValid(error))
    return false;
  if (max_repair_rounds < 0 || max_repair_rounds > 100) {
    if (error) *error = "max_repair_rounds must lie in 0..100";
    return false;
  }
  if (frame_margin < 0 || frame_margin > 64) {
    if (error) *error = "frame_margin must lie in 0..64";
    return false;
  }
  if (min_component_pixels < 0) {
    if (error) *error = "min_component_pixels must not be negative";
    return false;
  }
  return true;
}

InterpretationResult Interpret(const cv::Mat& skeleton, pattern::Side side,
                               const pattern::PatternSpec& spec, const InterpretationParams& params,
                               const cv::Mat& stripe_mask, const Cancellation& cancel) {
  if (skeleton.empty() || skeleton.type() != CV_8UC1)
    throw std::invalid_argument("Interpret: skeleton must be a non-empty CV_8UC1 image");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("Interpret: " + why);
  if (!spec.IsValid(&why)) throw std::invalid_argument("Interpret: pattern: " + why);

  InterpretationResult result;
  // The skeleton inside an empty frame, so that a corner at the image's edge
  // can take the stub the edge cut off (5.2.3.3); everything is shifted back
  // into image coordinates at the end.
  const int m = params.frame_margin;
  cv::Mat sk, mask;
  cv::compare(skeleton, 0, sk, cv::CMP_NE);
  cv::copyMakeBorder(sk, sk, m, m, m, m, cv::BORDER_CONSTANT, 0);
  cancel.ThrowIfRequested("the skeleton's frame");
  if (!stripe_mask.empty()) {
    if (stripe_mask.type() != CV_8UC1 || stripe_mask.size() != skeleton.size())
      throw std::invalid_argument("Interpret: stripe mask must be CV_8UC1 of the skeleton's size");
    // Stripes run on beyond the image's edge.
    cv::copyMakeBorder(stripe_mask, mask, m, m, m, m, cv::BORDER_REPLICATE);
  }
  const cv::Rect image(m, m, skeleton.cols, skeleton.rows);
  // The skeleton as it stands and every point, in image coordinates.
  auto finish = [&](InterpretationResult& r) {
    r.skeleton = sk(image).clone();
    ToImageFrame(image, &r);
  };
  // Thesis 4.4: skeleton pieces too small to be part of the pattern.
  if (params.min_component_pixels > 0)
    sk = extraction::RemoveSmallComponents(sk, params.min_component_pixels, cancel);
  cancel.ThrowIfRequested("the small components");
  PruneFalseJunctions(sk, side, params, cancel);
  cancel.ThrowIfRequested("the false junctions");

  // Thesis 5.2.1: the reference line first, sealed end to end.
  if (!TraceReferenceLine(sk, side, params.reference, &result.reference, &why)) {
    result.error = "reference line not found: " + why;
    finish(result);
    return result;
  }

  // Thesis 5.2.3.3: corners become junctions with a one-stroke stub.
  cancel.ThrowIfRequested("the reference line");
  result.corners = ExtendCorners(SkeletonGraph::Build(sk, params.graph, cancel), params.corners, sk,
                                 mask, image);

  // Thesis 5.2.3 and 5.1.4: trace boundary and loops, correct, retrace. The
  // graph of the last round is the final one: a round without repairs leaves
  // the skeleton as it was, so it is not built again.
  std::unique_ptr<SkeletonGraph> graph;
  std::unique_ptr<JunctionNetwork> network;
  std::vector<LoopRecord> loops;
  for (int round = 0;; ++round) {
    network.reset();  // it refers to the graph
    graph.reset();    // first, so that the new graph can take over its memory
    cancel.ThrowIfRequested("the repair rounds");
    graph = std::make_unique<SkeletonGraph>(SkeletonGraph::Build(sk, params.graph, cancel));
    cancel.ThrowIfRequested("the skeleton graph");
    network = std::make_unique<JunctionNetwork>(*graph, side, params.junction);
    loops = TraceLoops(*network);
    cancel.ThrowIfRequested("the loop tracing");
    if (!params.enable_repair || round == params.max_repair_rounds) break;
    if (round == 0)
      for (const LoopRecord& l : loops) ++result.loop_classes[l.cls];
    const std::vector<Repair> repairs = RepairRound(*network, loops, params.repair, sk);
    if (repairs.empty()) break;
    result.repairs.insert(result.repairs.end(), repairs.begin(), repairs.end());
  }
  if (!params.enable_repair)
    for (const LoopRecord& l : loops) ++result.loop_classes[l.cls];
  for (const LoopRecord& l : loops)
    if (l.cls == LoopClass::kBoundary) result.boundary.push_back(l);
  if (!LabelNetwork(*network, loops, result.reference, spec, params.labelling, &result.labelling,
                    &why)) {
    result.error = "reference line not found: " + why;
    finish(result);
    return result;
  }
  result.ok = true;
  finish(result);
  return result;
}

}  // namespace bsls::interpretation
