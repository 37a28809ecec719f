#include "track_geometry.h"

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "track_junctions.h"

namespace bsls::decoder::internal {

namespace {

// Whether verdict k of a geometry's per-junction list rules its junction
// out; a geometry that judges no junction one by one (a shorter list) rules
// none out.
bool RuledOut(const std::vector<char>& verdicts, size_t k) {
  return k < verdicts.size() && verdicts[k];
}

// Issue 25 parts 3-4 (docs/decoding.md, "Islands placed by the geometry"):
// the calibration's `geometry` judges line 0's component first: where it
// clearly puts the component at another shift (the track taken for line 0
// was another line in phase with it), the component moves there, or, off
// the slide, the frame is refused; its junctions the geometry rules out lose
// their labels. Then each island of `labels` takes the shift the geometry
// proves for it, less the junctions it rules out and those whose labels
// another junction already holds (a slide junction is seen once); where those
// are more than a tenth of the island, or any label would fall off the slide
// or disagree with its kind, the island stays unlabelled. Counts the islands
// placed and the component's move in `result`. With `may_move` false, a
// component the geometry does not confirm where it stands is refused.
void PlaceByGeometry(const interpretation::TrackNetwork& net, const pattern::PatternSpec& spec,
                     const WorkingScale& scale, const LabelGeometry& geometry, bool may_move,
                     interpretation::TrackLabels* labels, DecodeResult* result) {
  constexpr double kMaxDropped = 0.1;
  constexpr double kMaxRefuted = 1.0 / 3.0;
  std::vector<FramedJunction> labelled;
  std::vector<int> index;
  for (int j = 0; j < static_cast<int>(net.junctions.size()); ++j)
    if (labels->p[j] != interpretation::kUnlabelled) {
      labelled.push_back({scale.ToFull(net.junctions[j].position), labels->p[j], labels->v[j]});
      index.push_back(j);
    }
  auto on_slide = [&](int j, int p, int v) {
    return pattern::JunctionOnRowParity(spec, p, v) == net.junctions[j].kind;
  };
  auto lines_on_slide = [&](const std::vector<int>& line_p, int dp) {
    return std::all_of(line_p.begin(), line_p.end(),
                       [&](int lp) { return lp + dp >= 0 && lp + dp < spec.lines; });
  };

  std::string why;
  const auto own = geometry.PlaceIsland(labelled, labelled, &why);
  const bool moves = own && (own->dp != 0 || own->dq != 0);
  if (!may_move && (!own || moves)) {
    labels->ok = false;
    labels->error = own ? "the calibration's geometry puts the labels " + std::to_string(own->dp) +
                              " lines and " + std::to_string(own->dq) + " rows off"
                        : "the calibration's geometry cannot confirm the labels: " + why;
    return;
  }
  if (moves) {
    std::vector<int> line_p;
    for (int lp : labels->line_p)
      if (lp >= 0) line_p.push_back(lp);
    bool fits = lines_on_slide(line_p, own->dp);
    for (size_t k = 0; k < index.size() && fits; ++k)
      fits = on_slide(index[k], labelled[k].p + own->dp, labelled[k].q + own->dq);
    if (!fits) {
      labels->ok = false;
      labels->error = "the calibration's geometry puts the labels " + std::to_string(own->dp) +
                      " lines off, off the slide: the line taken for line 0 is not line 0";
      return;
    }
    for (size_t k = 0; k < index.size(); ++k) {
      labels->p[index[k]] += own->dp;
      labels->v[index[k]] += own->dq;
      labelled[k].p += own->dp;
      labelled[k].q += own->dq;
    }
    for (int& lp : labels->line_p)
      if (lp >= 0) lp += own->dp;
    result->line_zero_moved = own->dp;
  }
  // A label the geometry rules out is not reported; where it rules out more
  // than a third of the component, the component's labels are refuted.
  const std::vector<char> out = geometry.RuleOut(labelled);
  const auto refuted = std::count(out.begin(), out.end(), 1);
  if (refuted > kMaxRefuted * static_cast<double>(labelled.size())) {
    labels->ok = false;
    labels->error = "the calibration's geometry refutes the labels: " + std::to_string(refuted) +
                    " of " + std::to_string(labelled.size()) +
                    " junctions of line 0's part are off their rows";
    return;
  }
  std::vector<FramedJunction> kept;
  for (size_t k = 0; k < index.size(); ++k) {
    if (RuledOut(out, k)) {
      labels->p[index[k]] = labels->v[index[k]] = interpretation::kUnlabelled;
      ++result->ruled_out;
    } else {
      kept.push_back(labelled[k]);
    }
  }
  labelled = std::move(kept);
  std::set<std::pair<int, int>> taken;
  for (const FramedJunction& j : labelled) taken.emplace(j.p, j.q);
  for (const interpretation::TrackLabels::Island& island : labels->islands) {
    std::vector<FramedJunction> members;
    for (size_t k = 0; k < island.junctions.size(); ++k)
      members.push_back(
          {scale.ToFull(net.junctions[island.junctions[k]].position), island.p[k], island.v[k]});
    const std::optional<LabelShift> shift = geometry.PlaceIsland(labelled, members, &why);
    if (!shift || !lines_on_slide(island.line_p, shift->dp)) continue;
    std::vector<char> keep(island.junctions.size(), 0);
    bool fits = true;
    size_t dropped = 0;
    for (size_t k = 0; k < island.junctions.size() && fits; ++k) {
      const int p = island.p[k] + shift->dp, v = island.v[k] + shift->dq;
      fits = on_slide(island.junctions[k], p, v);
      keep[k] = !RuledOut(shift->ruled_out, k) && !taken.contains({p, v});
      dropped += !keep[k];
    }
    if (!fits || dropped > kMaxDropped * static_cast<double>(island.junctions.size())) continue;
    for (size_t k = 0; k < island.junctions.size(); ++k) {
      if (!keep[k]) continue;
      labels->p[island.junctions[k]] = island.p[k] + shift->dp;
      labels->v[island.junctions[k]] = island.v[k] + shift->dq;
    }
    result->ruled_out += static_cast<int>(dropped);
    for (size_t k = 0; k < island.lines.size(); ++k)
      labels->line_p[island.lines[k]] = island.line_p[k] + shift->dp;
    ++result->islands_placed;
  }
}

}  // namespace

// Labels with a calibration: line 0's chain of candidates nearest the
// centre row (thesis 5.2.1), its component judged by the geometry
// (PlaceByGeometry). Where that fails, the other chains are tried in turn
// (track_chain.reference_tries), each kept only where the geometry confirms
// its labels where they stand: a line whose inner neighbours are hidden
// looks like line 0 in the image, but not in depth. The first chain's
// failure is the one reported.
interpretation::TrackLabels LabelWithGeometry(const interpretation::TrackNetwork& net,
                                              pattern::Side side, const DecodeParams& params,
                                              const WorkingScale& scale,
                                              const LabelGeometry& geometry,
                                              const Cancellation& cancel, DecodeResult* result) {
  interpretation::TrackLabellingParams lp = params.track_chain.labelling;
  // The geometry checks every junction's row: one row count across a gap
  // joins a part of line 0 (TrackLabellingParams::min_seeded_half_votes).
  lp.min_seeded_half_votes = 1;
  interpretation::TrackLabels first;
  for (int choice = 0; choice <= params.track_chain.reference_tries; ++choice) {
    lp.reference_choice = choice;
    interpretation::TrackLabels labels =
        interpretation::LabelTracks(net, side, params.spec, lp, cancel);
    if (labels.ok) {
      DecodeResult placed;
      PlaceByGeometry(net, params.spec, scale, geometry, /*may_move=*/choice == 0, &labels,
                      &placed);
      if (labels.ok) {
        result->line_zero_moved = placed.line_zero_moved;
        result->ruled_out += placed.ruled_out;
        result->islands_placed += placed.islands_placed;
        result->reference_choice = choice;
        return labels;
      }
    }
    cancel.ThrowIfRequested("the labelling");
    const bool more = choice + 1 < labels.reference_choices;
    if (choice == 0) first = std::move(labels);
    if (!more) break;
  }
  return first;
}

// The junctions as they leave the decoder, at their sub-pixel places: a
// label the geometry rules out there is taken back and the junction listed
// unlabelled (its place can differ from the track junction's judged before).
void RuleOutPlaced(const LabelGeometry& geometry, DecodeResult* result) {
  std::vector<FramedJunction> placed;
  for (const DecodedJunction& j : result->junctions) placed.push_back({j.position, j.p, j.q});
  const std::vector<char> out = geometry.RuleOut(placed);
  std::vector<DecodedJunction> kept;
  for (size_t k = 0; k < result->junctions.size(); ++k) {
    const DecodedJunction& j = result->junctions[k];
    if (RuledOut(out, k)) {
      if (j.interpolated) continue;  // never seen: nothing to list
      result->unlabelled.push_back({j.position, j.kind});
      ++result->ruled_out;
    } else {
      kept.push_back(j);
    }
  }
  result->junctions = std::move(kept);
  SortByRow(&result->unlabelled);
}

}  // namespace bsls::decoder::internal
