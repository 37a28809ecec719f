#include "bsls/interpretation/interpreter.h"

#include <stdexcept>


#include "bsls/extraction/pruning.h"
#include "bsls/interpretation/junction_detect.h"

namespace bsls::interpretation {
namespace {

// Thesis 5.2.3.1 stage 8: a junction whose window shows fewer than three
// paths is a degree-2 point with a noisy pixel or two; prune its short spurs.
int PruneFalseJunctions(cv::Mat& sk, pattern::Side side, const InterpretationParams& params) {
  const SkeletonGraph g = SkeletonGraph::Build(sk, params.graph);
  int pruned = 0;
  for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n) {
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

}  // namespace

bool InterpretationParams::IsValid(std::string* error) const {
  if (!graph.IsValid(error) || !junction.IsValid(error) || !corners.IsValid(error) || !reference.IsValid(error) ||
      !repair.IsValid(error) || !labelling.IsValid(error))
    return false;
  if (max_repair_rounds < 0 || max_repair_rounds > 100) {
    if (error) *error = "max_repair_rounds must lie in 0..100";
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
                               const cv::Mat& stripe_mask) {
  if (skeleton.empty() || skeleton.type() != CV_8UC1)
    throw std::invalid_argument("Interpret: skeleton must be a non-empty CV_8UC1 image");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("Interpret: " + why);
  if (!spec.IsValid(&why)) throw std::invalid_argument("Interpret: pattern: " + why);

  InterpretationResult result;
  cv::Mat sk;
  cv::compare(skeleton, 0, sk, cv::CMP_NE);
  // Thesis 4.4: skeleton pieces too small to be part of the pattern.
  if (params.min_component_pixels > 0)
    sk = extraction::RemoveSmallComponents(sk, params.min_component_pixels);
  PruneFalseJunctions(sk, side, params);

  // Thesis 5.2.1: the reference line first, sealed end to end.
  if (!TraceReferenceLine(sk, side, params.reference, &result.reference, &why)) {
    result.error = "reference line not found: " + why;
    result.skeleton = sk;
    return result;
  }

  // Thesis 5.2.3.3: corners become junctions with a one-stroke stub.
  result.corners =
      ExtendCorners(SkeletonGraph::Build(sk, params.graph), params.corners, sk, stripe_mask);

  // Thesis 5.2.3 and 5.1.4: trace boundary and loops, correct, retrace.
  for (int round = 0; params.enable_repair && round < params.max_repair_rounds; ++round) {
    const SkeletonGraph graph = SkeletonGraph::Build(sk, params.graph);
    const JunctionNetwork network(graph, side, params.junction);
    const std::vector<LoopRecord> loops = TraceLoops(network);
    if (round == 0)
      for (const LoopRecord& l : loops) ++result.loop_classes[l.cls];
    const std::vector<Repair> repairs = RepairRound(network, loops, params.repair, sk);
    if (repairs.empty()) break;
    result.repairs.insert(result.repairs.end(), repairs.begin(), repairs.end());
  }

  const SkeletonGraph graph = SkeletonGraph::Build(sk, params.graph);
  const JunctionNetwork network(graph, side, params.junction);
  const std::vector<LoopRecord> loops = TraceLoops(network);
  if (!params.enable_repair)
    for (const LoopRecord& l : loops) ++result.loop_classes[l.cls];
  for (const LoopRecord& l : loops)
    if (l.cls == LoopClass::kBoundary) result.boundary.push_back(l);
  result.skeleton = sk;
  if (!LabelNetwork(network, loops, result.reference, spec, params.labelling, &result.labelling,
                    &why)) {
    result.error = "reference line not found: " + why;
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace bsls::interpretation
