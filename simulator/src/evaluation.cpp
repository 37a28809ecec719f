#include "bsls/simulator/evaluation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace bsls::simulator {

std::string LabelScore::Summary() const {
  std::ostringstream s;
  s << "truth " << truth << ", found " << found << " (" << 100.0 * Recall() << "%), wrong p "
    << wrong_p << ", wrong v " << wrong_v << ", unmatched " << unmatched << ", v offset "
    << v_offset << ", position rms " << position_rms << " px";
  auto list = [&s](const char* what, const std::vector<PointLabel>& v) {
    if (v.empty()) return;
    s << "; " << what << ":";
    for (size_t i = 0; i < v.size() && i < 12; ++i)
      s << " (" << v[i].p << "," << v[i].v << ")@" << cvRound(v[i].position.x) << ","
        << cvRound(v[i].position.y);
  };
  list("missed", missed);
  list("wrong", wrong);
  return s.str();
}

LabelScore ScoreLabels(const std::vector<PointLabel>& truth, const std::vector<PointLabel>& decoded,
                       double reach) {
  LabelScore score;
  score.truth = static_cast<int>(truth.size());
  std::vector<int> match(truth.size(), -1);
  std::vector<char> used(decoded.size(), 0);
  // Greedy by distance: all pairs within reach, nearest first.
  std::vector<std::tuple<double, int, int>> pairs;
  for (size_t t = 0; t < truth.size(); ++t)
    for (size_t d = 0; d < decoded.size(); ++d) {
      const double dist = std::hypot(truth[t].position.x - decoded[d].position.x,
                                     truth[t].position.y - decoded[d].position.y);
      if (dist <= reach) pairs.emplace_back(dist, static_cast<int>(t), static_cast<int>(d));
    }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [dist, t, d] : pairs) {
    if (match[t] >= 0 || used[d]) continue;
    match[t] = d;
    used[d] = 1;
  }
  std::map<int, int> offsets;
  for (size_t t = 0; t < truth.size(); ++t)
    if (match[t] >= 0 && decoded[match[t]].p == truth[t].p)
      ++offsets[decoded[match[t]].v - truth[t].v];
  int best = 0;
  for (const auto& [off, n] : offsets)
    if (n > best) {
      best = n;
      score.v_offset = off;
    }
  double sum2 = 0;
  int n2 = 0;
  for (size_t t = 0; t < truth.size(); ++t) {
    if (match[t] < 0) {
      score.missed.push_back(truth[t]);
      continue;
    }
    ++score.found;
    const PointLabel& d = decoded[match[t]];
    if (d.p != truth[t].p) {
      ++score.wrong_p;
      score.wrong.push_back(truth[t]);
    } else if (d.v - truth[t].v != score.v_offset) {
      ++score.wrong_v;
      score.wrong.push_back(truth[t]);
    } else {
      sum2 += std::pow(d.position.x - truth[t].position.x, 2) +
              std::pow(d.position.y - truth[t].position.y, 2);
      ++n2;
    }
  }
  for (size_t d = 0; d < decoded.size(); ++d) score.unmatched += !used[d];
  score.position_rms = n2 ? std::sqrt(sum2 / n2) : 0.0;
  return score;
}

std::vector<PointLabel> VisibleJunctions(const GroundTruth& truth) {
  std::vector<PointLabel> out;
  for (const TruthJunction& j : truth.junctions)
    if (j.visible) out.push_back({j.p, j.v, {j.image.x(), j.image.y()}});
  return out;
}

std::vector<LinePoints> TruthLines(const GroundTruth& truth) {
  std::vector<LinePoints> out;
  for (const TruthLine& line : truth.lines) {
    LinePoints l{line.p, {}};
    for (const auto& p : line.points) l.points.emplace_back(p.x(), p.y());
    out.push_back(std::move(l));
  }
  return out;
}

LineScore ScoreLines(const std::vector<LinePoints>& truth, const std::vector<LinePoints>& decoded) {
  std::map<int, std::multimap<long, double>> rows;
  for (const LinePoints& line : truth)
    for (const cv::Point2d& p : line.points) rows[line.p].emplace(std::lround(p.y), p.x);
  LineScore score;
  double sum2 = 0;
  for (const LinePoints& line : decoded) {
    const auto& r = rows[line.p];
    for (const cv::Point2d& p : line.points) {
      const auto range = r.equal_range(std::lround(p.y));
      if (range.first == range.second) continue;
      double best = 1e300;
      for (auto it = range.first; it != range.second; ++it)
        best = std::min(best, std::abs(it->second - p.x));
      sum2 += best * best;
      ++score.points;
    }
  }
  score.rms = score.points ? std::sqrt(sum2 / score.points) : 0.0;
  return score;
}

}  // namespace bsls::simulator
