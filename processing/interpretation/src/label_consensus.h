// Private to bsls::interpretation: labels proven by agreement over the
// junction graph (thesis 5.1.4.9, checked the way the one-shot grid
// decoders check theirs: consistency over the grid graph).
//
// Junctions are joined by links that each say how the label changes from
// one end to the other (dp, dv): a step along a line (dv rows), a segment
// (dp = 1). A link of a brick that closes (thesis 5.1.4.1, a complete loop)
// is trusted. The junctions joined by trusted links form patches, each
// labelled relative to itself; a patch whose trusted links contradict each
// other loses the contradicting links. Patches are then joined into
// components where the other links between them agree: at least
// `min_support` links giving the same shift, and few giving another. A
// single link is never enough, since a line followed across an occluding
// edge, a segment end that met the wrong line or a row count across a gap
// each make one wrong link; two independent wrong links that agree are rare.
// The component holding most of line 0's junctions (the seeds, p = 0) is
// labelled; every other junction stays unlabelled rather than guessed.
//
// The brick pattern's labels keep the parity of p + v with the junction's
// kind (direct: even, corresponding: odd; contracts section 1), so every
// shift between patches has dp + dv even; a link implying an odd one is
// wrong by construction.
#ifndef BSLS_INTERPRETATION_SRC_LABEL_CONSENSUS_H_
#define BSLS_INTERPRETATION_SRC_LABEL_CONSENSUS_H_

#include <vector>

namespace bsls::interpretation::internal {

struct ConsensusLink {
  int a = -1;  // junction at one end
  int b = -1;  // junction at the other
  int dp = 0;  // label of b minus label of a
  int dv = 0;
  bool trusted = false;  // a link of a closed brick
  // A step along a line whose row spacing the step before or after it on
  // the same unbroken line repeats: alone, enough for a lone junction.
  bool smooth = false;
  // The line pitch at its two ends differs beyond what a smooth surface
  // gives, and one end's lines crowd (a grazing surface, an occluding
  // edge): half a vote for a lone junction.
  bool abrupt = false;
  // A step across a break in its line (rows counted over the gap): half a
  // vote for joining two components.
  bool gap = false;
};

struct ConsensusParams {
  // Links that must agree on the shift between two components, >= 1.
  int min_support = 2;
  // Links giving another shift (or an impossible one) allowed per agreeing
  // link, [0, 1).
  double max_dissent = 0.34;
  // A component not joined to line 0's is kept as an island (labelled
  // relative to itself, for a calibration to place) from this many
  // junctions; 0: none kept.
  int min_island = 12;
  // A part of line 0 joins through links whose shift of rows carries at
  // least this many half votes (a step across a gap is one, any other link
  // two), >= 1: the seeds confirm p, not v.
  int min_seeded_half_votes = 2;
  // Of the links agreeing on a join of two components, at least this many
  // are whole (not a step across a gap in a line), >= 0: where an occluding
  // edge cuts the lines of the surface behind it, a line there and one of
  // the surface in front meet end to end, and steps across that "gap" can
  // agree on a join lines off.
  int min_whole_links = 1;
};
// A lone junction (in no closed brick) at the pattern's edge joins the
// labelled ones through two agreeing links, or through one smooth step
// along its line and no link disagreeing.

struct Consensus {
  std::vector<int> p;          // per junction: line relative to line 0, or kUnlabelled
  std::vector<int> v;          // per junction: row, relative (any even offset), or kUnlabelled
  int contradicted_links = 0;  // trusted links dropped as contradicting their patch
  // Components not joined to line 0's of at least min_island junctions:
  // per junction its island (0 .. islands-1) or -1, and its label relative
  // to the island (p + v keeps the junction's parity, so an island's labels
  // are known up to one shift with dp + dv even).
  int islands = 0;
  std::vector<int> island;
  std::vector<int> island_p;
  std::vector<int> island_v;
};

// Labels `odd_kind.size()` junctions (odd_kind[j]: 1 for a corresponding
// junction, whose p + v is odd; 0 for a direct one) from `links` and the
// `seeds` on line 0 (p = 0). Only the component with most seeds agreeing
// on its p is labelled, and only where it has at least `min_seeds` of
// them; the other large components are returned as islands. Pure function.
Consensus LabelByConsensus(const std::vector<char>& odd_kind,
                           const std::vector<ConsensusLink>& links, const std::vector<int>& seeds,
                           int min_seeds, const ConsensusParams& params);

}  // namespace bsls::interpretation::internal

#endif  // BSLS_INTERPRETATION_SRC_LABEL_CONSENSUS_H_
