#include "missing_junctions.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>

namespace bsls::decoder::internal {
namespace {

// x of `line` at row y, interpolated between its centres on the rows
// either side, where from row y0 to row y1 no run of rows longer than
// max_gap lacks a centre (nothing hides the line there); nullopt otherwise.
std::optional<double> XAcross(const DecodedLine& line, double y0, double y1, double y,
                              double max_gap) {
  const std::vector<cv::Point2d>& points = line.points;  // by y
  auto first = std::lower_bound(points.begin(), points.end(), y0,
                                [](const cv::Point2d& p, double row) { return p.y < row; });
  auto last = std::upper_bound(points.begin(), points.end(), y1,
                               [](double row, const cv::Point2d& p) { return row < p.y; });
  if (first == last || first->y - y0 > max_gap || y1 - std::prev(last)->y > max_gap)
    return std::nullopt;
  std::optional<double> x;
  for (auto it = first; it != last; ++it) {
    if (it != first && it->y - std::prev(it)->y > max_gap + 1) return std::nullopt;
    if (it->y >= y && !x) {
      if (it == first || it->y == y) {
        x = it->x;
      } else {
        const cv::Point2d& before = *std::prev(it);
        x = before.x + (it->x - before.x) * (y - before.y) / (it->y - before.y);
      }
    }
  }
  return x;
}

}  // namespace

void PlaceMissingJunctions(const std::vector<DecodedLine>& lines, const pattern::PatternSpec& spec,
                           int q_offset, int max_run, double same_px,
                           std::vector<DecodedJunction>* junctions,
                           std::vector<UnlabelledJunction>* unlabelled) {
  if (max_run <= 0) return;
  std::map<int, const DecodedLine*> line_of;
  for (const DecodedLine& l : lines) line_of[l.p] = &l;
  std::map<int, std::vector<const DecodedJunction*>> on_line;
  for (const DecodedJunction& j : *junctions) on_line[j.p].push_back(&j);

  std::vector<DecodedJunction> added;
  for (auto& [p, seen] : on_line) {
    const auto line = line_of.find(p);
    if (line == line_of.end()) continue;
    std::sort(seen.begin(), seen.end(),
              [](const DecodedJunction* a, const DecodedJunction* b) { return a->q < b->q; });
    for (size_t k = 0; k + 1 < seen.size(); ++k) {
      const DecodedJunction& a = *seen[k];
      const DecodedJunction& b = *seen[k + 1];
      // The pattern's junctions of line p between the two.
      std::vector<std::pair<int, pattern::JunctionKind>> between;
      for (int q = a.q + 1; q < b.q && static_cast<int>(between.size()) <= max_run; ++q)
        if (const auto kind = pattern::JunctionOnRowParity(spec, p, q - q_offset))
          between.push_back({q, *kind});
      if (between.empty() || static_cast<int>(between.size()) > max_run) continue;
      if (!(b.position.y > a.position.y)) continue;
      // px a row of the pattern: the line may lack centres over half of one
      // (beside a junction, a stroke's light), not more.
      const double row = (b.position.y - a.position.y) / (b.q - a.q);
      for (const auto& [q, kind] : between) {
        const double y = a.position.y + row * (q - a.q);
        const auto x = XAcross(*line->second, a.position.y, b.position.y, y, 0.5 * row);
        if (!x) break;
        DecodedJunction j;
        j.position = {*x, y};
        j.p = p;
        j.q = q;
        j.kind = kind;
        j.interpolated = true;
        added.push_back(j);
      }
    }
  }
  if (added.empty()) return;
  // An unlabelled junction where one is placed is that junction, seen.
  std::erase_if(*unlabelled, [&](const UnlabelledJunction& u) {
    return std::any_of(added.begin(), added.end(), [&](const DecodedJunction& j) {
      return j.kind == u.kind && cv::norm(j.position - u.position) <= same_px;
    });
  });
  junctions->insert(junctions->end(), added.begin(), added.end());
  std::sort(junctions->begin(), junctions->end(),
            [](const DecodedJunction& a, const DecodedJunction& b) {
              return std::tie(a.p, a.q) < std::tie(b.p, b.q);
            });
}

}  // namespace bsls::decoder::internal
