// Labelling of thesis 5.1.4.9 on the track network (ridge_tracks.h): line 0
// is found (5.2.1), its junctions are numbered along it, and labels spread
// from them along lines (v changes by one row per junction, the kinds
// alternating) and across segments (p changes by one, v stays).
//
// Line 0 is the lit line on the unlit side of the pattern: the "moving
// column" of 5.2.1 swept in from that side stops on it in each row, so a
// line track that is outermost in most of its rows and carries direct
// junctions only (its segments all leave towards p = 1) is part of line 0.
// Its junctions are numbered two rows a step of its row spacing; two closer
// than one step are not both line 0's and neither seeds. A break in a line
// or a lost segment does not stop the labels: every junction is reached
// through its brick's other junctions, which is what the thesis's repairs
// (5.1.4.3-5.1.4.8) restore the paths for. Links of closed bricks are
// trusted over any other, and a row count across a gap of line 0 over any
// path with an untrusted link.
//
// A label must agree with the junction's kind (a direct junction on line p
// lies on a row v = p mod 2); a junction whose neighbours mostly disagree
// with it is dropped rather than guessed. v is relative: line 0's junction
// nearest the image's centre row gets v = 0 (thesis point O).
//
// Image coordinates: x right, y down.
//
// Thread-safety: pure function of its arguments.
#ifndef BSLS_INTERPRETATION_TRACK_LABELLING_H_
#define BSLS_INTERPRETATION_TRACK_LABELLING_H_

#include <climits>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"
#include "bsls/interpretation/ridge_tracks.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::interpretation {

struct TrackLabellingParams {
  // A line track is a candidate for line 0 when it is the outermost on the
  // unlit side in at least this fraction of its rows, (0, 1].
  double reference_share = 0.5;
  // Which chain of candidates is taken for line 0, >= 0: 0 the one through
  // the candidate nearest the centre row (thesis 5.2.1), k the one through
  // the k-th nearest candidate not in an earlier chain. Without a
  // calibration only 0 is safe: a line whose inner neighbours are hidden
  // looks like line 0; a calibration tries the others and keeps one only
  // where its geometry confirms the labels (decoder: reference_tries).
  int reference_choice = 0;
  // Line 0 is followed from candidate to candidate across gaps of up to
  // this (px from one's end to the next's start, the next starting lower), > 0;
  double follow_distance = 24.0;
  // it carries at least this many direct junctions, >= 1,
  int min_reference_junctions = 2;
  // and at most this fraction of corresponding ones, [0, 1].
  double max_inner_fraction = 0.2;
  // A step along a line between junctions must fit a whole number of rows
  // (odd when their kinds alternate, even otherwise) to within this fraction
  // of a row, (0, 0.5]; at most max_rows rows, >= 1.
  double max_row_miss = 0.35;
  int max_rows = 8;
  // Spacing samples a line track needs to judge its steps by its own row
  // spacing instead of the frame's, >= 1.
  int min_own_spacings = 3;
  // Labels spread from line 0 only between groups of closed bricks that at
  // least min_support links join with the same shift of labels (>= 1), and
  // at most max_dissent links per agreeing one join otherwise, [0, 1).
  int min_support = 2;
  double max_dissent = 0.34;
  // A part not joined to line 0's of at least this many junctions is kept
  // as an island, labelled relative to itself for a calibration to place
  // (TrackLabels::islands); 0 keeps none.
  int min_island = 12;
  // A part of line 0 cut off from the rest (the nose's tip) joins it where
  // both sets of seeds confirm p and the links give its rows with at least
  // this many half votes (a row count across a gap is one, another link
  // two), >= 1. Without a calibration a whole vote: one count across a gap
  // an occluding edge hides may be rows off. With one, the geometry checks
  // every junction's row, and one count is enough (the decoder sets 1).
  int min_seeded_half_votes = 2;
  // Two groups of closed bricks join only where at least this many of the
  // links agreeing on it are whole, not steps across a gap in a line (>= 0).
  // Where an occluding edge cuts the lines of the surface behind it (the
  // base plane below a cylinder), those lines end on the edge and lines of
  // the surface in front go on from there: bridged as gaps, their steps
  // agree on a join some lines off.
  int min_whole_links = 1;
  // Whether a brick whose top or bottom segment is abrupt (the line pitch
  // at its two ends jumps, one end's lines crowded) still closes and its
  // links are trusted. Off: on a surface seen edge-on (a ball's limb),
  // lines crowd until the loop of a brick closes over lines that are not
  // neighbours, and a whole patch takes a shift of several lines.
  bool close_abrupt_bricks = false;

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

constexpr int kUnlabelled = INT_MIN;

struct TrackLabels {
  bool ok = false;
  std::string error;           // why nothing could be labelled (ok == false)
  std::vector<int> p;          // per junction of the network: its line, or kUnlabelled
  std::vector<int> v;          // per junction: its slide row (relative), or kUnlabelled
  std::vector<int> line_p;     // per line track: the p most of its labelled junctions carry, or -1
  std::vector<int> reference;  // the line tracks taken for line 0
  int conflicts = 0;           // labels dropped because their neighbours disagreed
  // Chains of line-0 candidates known to the frame: those followed up to
  // reference_choice, and one more where a candidate is left for another.
  int reference_choices = 0;
  double row_spacing = 0;  // px between rows along a line: the median over the frame

  // A part of the network not joined to line 0's, proven in itself: its
  // junctions and line tracks labelled relative to one another, so the
  // labels are known up to one shift (dp, dv) with dp + dv even. Without a
  // calibration to place it, it stays unlabelled.
  struct Island {
    std::vector<int> junctions;  // indices into the network's junctions
    std::vector<int> p, v;       // per entry of `junctions`: its relative label
    std::vector<int> lines;      // line tracks most of whose junctions are the island's
    std::vector<int> line_p;     // per entry of `lines`: its relative p
  };
  std::vector<Island> islands;
};

// Labels the junctions and line tracks of `network` for the brick slide of
// `side`. Fails (ok == false, with the reason) when no line 0 carrying
// enough direct junctions is found. Throws std::invalid_argument for invalid
// params, bsls::Cancelled when `cancel` asks to stop.
TrackLabels LabelTracks(const TrackNetwork& network, pattern::Side side,
                        const pattern::PatternSpec& spec, const TrackLabellingParams& params = {},
                        const Cancellation& cancel = {});

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_TRACK_LABELLING_H_
