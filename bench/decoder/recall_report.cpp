// Recall report of the decoder against the simulator's ground truth: the
// frames of tests/decoder (noise sigma 3, 512 x 512 unless --size), faces of
// seeds 1..N (--seeds, default 5) and the test objects (plane, ramp, ball;
// seed 7), both sides. For each frame one line: lit and visible junctions,
// found within 2.5 px, wrong p / wrong q, decoded junctions with no truth
// near, junction position RMS, line centre RMS; then every missed junction
// with what explains it where the truth tells:
//   border     its centre within 1 px of the image edge
//   placed D   a decoded junction with its label lies D px away (beyond reach)
//   near X     an unlabelled-for-it decoded junction lies within 5 px (label X)
//   outline B  the face's outline (shadow, silhouette) is B px away
//   grazing C  the projector's light meets the surface at cos C < 0.35
// Not a Google benchmark: a plain program so that its output can be diffed.
//
//   recall_report [--seeds N] [--size PX] [--quiet] [--extra] [--crops DIR]
//                 [--chain tracks|skeleton]
//     --quiet   summary lines only; --extra  also list unmatched decoded junctions;
//     --crops   write a PNG around each missed (and, prefixed wrong_, each
//               wrongly labelled) junction into DIR (6x: the frame, skeleton
//               red, decoded line centres yellow, decoded junctions blue, the
//               truth junction green)
//     --chain   the decoding chain (DecodeParams::chain; default: the decoder's)
// For experiments, the track chain's main parameters can be overridden from
// the environment: BSLS_TRACK_STEP (TrackParams::max_step), BSLS_TRACK_SIGMA
// (smoothing_sigma), BSLS_TRACK_PROMINENCE and BSLS_TRACK_WINDOW (RidgeParams).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/simulator/evaluation.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace {

using bsls::pattern::Side;
using bsls::simulator::SurfaceKind;

constexpr double kMatchReach = 2.5;  // px, as tests/decoder
constexpr double kNoiseSigma = 3.0;  // grey levels
constexpr std::uint32_t kObjectSeed = 7;

struct Options {
  int seeds = 5;
  int size = 512;
  bool quiet = false;
  bool extra = false;
  std::string crops;  // folder for the crops of missed junctions; empty: none
  bsls::decoder::DecodeChain chain = bsls::decoder::DecodeParams{}.chain;
};

struct Totals {
  int frames = 0, truth = 0, found = 0, wrong = 0;
  double worst_recall = 1.0;
};

// A 49 x 49 px crop around `at`, scaled 6x, with the decode drawn on it.
void WriteCrop(const std::string& path, const cv::Mat& grey, const bsls::decoder::DecodeResult& r,
               cv::Point2d at) {
  constexpr int kHalf = 24, kScale = 6;
  const cv::Rect box =
      cv::Rect(cvRound(at.x) - kHalf, cvRound(at.y) - kHalf, 2 * kHalf + 1, 2 * kHalf + 1) &
      cv::Rect(0, 0, grey.cols, grey.rows);
  if (box.empty()) return;
  cv::Mat big;
  cv::resize(grey(box), big, {}, kScale, kScale, cv::INTER_NEAREST);
  cv::cvtColor(big, big, cv::COLOR_GRAY2BGR);
  // Pixel (x, y) of the frame is centred at ((x - box.x + 0.5) * kScale, ...) in the crop.
  auto to = [&](cv::Point2d p) {
    return cv::Point(cvRound((p.x - box.x + 0.5) * kScale), cvRound((p.y - box.y + 0.5) * kScale));
  };
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x)
      if (r.skeleton.at<uchar>(y, x))
        cv::circle(big, to({double(x), double(y)}), 1, {0, 0, 255}, -1);
  for (const auto& line : r.lines)
    for (const auto& p : line.points)
      if (box.contains(cv::Point(cvRound(p.x), cvRound(p.y))))
        cv::circle(big, to(p), 1, {0, 255, 255}, -1);
  for (const auto& j : r.junctions) {
    if (!box.contains(cv::Point(cvRound(j.position.x), cvRound(j.position.y)))) continue;
    cv::circle(big, to(j.position), 4, {255, 0, 0}, 2);
    cv::putText(big, std::to_string(j.p) + "," + std::to_string(j.q),
                to(j.position) + cv::Point(6, -6), cv::FONT_HERSHEY_SIMPLEX, 0.4, {255, 128, 0}, 1);
  }
  cv::drawMarker(big, to(at), {0, 255, 0}, cv::MARKER_CROSS, 14, 2);
  cv::imwrite(path, big);
}

std::string Reason(const bsls::simulator::TruthJunction& t, const cv::Point2d& at,
                   const std::vector<bsls::simulator::PointLabel>& decoded, int v_offset, int w,
                   int h) {
  std::string out;
  char buf[96];
  if (at.x < 0.5 || at.y < 0.5 || at.x > w - 1.5 || at.y > h - 1.5) out += " border";
  double same = 1e9, near = 1e9;
  const bsls::simulator::PointLabel* nearest = nullptr;
  for (const auto& d : decoded) {
    const double dist = std::hypot(d.position.x - at.x, d.position.y - at.y);
    if (d.p == t.p && d.v - v_offset == t.v) same = std::min(same, dist);
    if (dist < near) {
      near = dist;
      nearest = &d;
    }
  }
  if (same < 1e8) {
    std::snprintf(buf, sizeof buf, " placed %.1f", same);
    out += buf;
  } else if (nearest && near < 5.0) {
    std::snprintf(buf, sizeof buf, " near (%d,%d)@%.1f", nearest->p, nearest->v - v_offset, near);
    out += buf;
  } else {
    out += " not-decoded";
  }
  if (t.boundary_distance_px < 6.0) {
    std::snprintf(buf, sizeof buf, " outline %.1f", t.boundary_distance_px);
    out += buf;
  }
  if (t.cos_incidence < 0.35) {
    std::snprintf(buf, sizeof buf, " grazing %.2f", t.cos_incidence);
    out += buf;
  }
  return out;
}

void Report(SurfaceKind kind, Side side, std::uint32_t seed, const Options& o, Totals* totals) {
  bsls::simulator::ThesisSceneOptions options;
  options.rig.width = o.size;
  options.rig.height = o.size;
  bsls::simulator::RenderParams params;
  params.noise_sigma = kNoiseSigma;
  params.seed = seed;
  const bsls::simulator::Frame frame =
      bsls::simulator::Render(bsls::simulator::ThesisScene(side, kind, options), params);
  const auto t0 = std::chrono::steady_clock::now();
  bsls::decoder::DecodeParams decode;
  decode.chain = o.chain;
  if (const char* v = std::getenv("BSLS_TRACK_STEP"))
    decode.track_chain.tracks.max_step = std::atof(v);
  if (const char* v = std::getenv("BSLS_TRACK_SIGMA"))
    decode.track_chain.smoothing_sigma = std::atof(v);
  if (const char* v = std::getenv("BSLS_TRACK_PROMINENCE"))
    decode.track_chain.ridge.min_prominence = std::atoi(v);
  if (const char* v = std::getenv("BSLS_TRACK_WINDOW"))
    decode.track_chain.ridge.half_window = std::atoi(v);
  if (const char* v = std::getenv("BSLS_TRACK_SEGCOLS"))
    decode.track_chain.segment_columns = std::atoi(v);
  if (const char* v = std::getenv("BSLS_TRACK_FITROWS")) decode.junction_fit_rows = std::atoi(v);
  const bsls::decoder::DecodeResult r = bsls::decoder::Decode(frame.image, side, decode);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const std::string name = std::string(bsls::simulator::ToString(kind)) + " " +
                           std::string(bsls::pattern::ToString(side)) + " seed " +
                           std::to_string(seed);
  if (!r.ok) {
    std::printf("%-22s FAILED: %s\n", name.c_str(), r.error.c_str());
    ++totals->frames;
    totals->worst_recall = 0.0;
    return;
  }
  // The truth's visible junctions, kept with their records for the reasons.
  std::vector<const bsls::simulator::TruthJunction*> records;
  for (const auto& j : frame.truth.junctions)
    if (j.visible) records.push_back(&j);
  const std::vector<bsls::simulator::PointLabel> truth =
      bsls::simulator::VisibleJunctions(frame.truth);
  std::vector<bsls::simulator::PointLabel> decoded;
  for (const auto& j : r.junctions) decoded.push_back({j.p, j.q, j.position});
  const double reach = kMatchReach * o.size / 512.0;
  const bsls::simulator::LabelScore s = bsls::simulator::ScoreLabels(truth, decoded, reach);
  std::vector<bsls::simulator::LinePoints> lines;
  for (const auto& line : r.lines) lines.push_back({line.p, line.points});
  const bsls::simulator::LineScore ls =
      bsls::simulator::ScoreLines(bsls::simulator::TruthLines(frame.truth), lines);
  std::printf(
      "%-22s truth %4d found %4d recall %6.2f %%  wrong p %d q %d  unmatched %2d  "
      "pos rms %.3f  line rms %.3f px (%d pts)  %.1f ms\n",
      name.c_str(), s.truth, s.found, 100.0 * s.Recall(), s.wrong_p, s.wrong_v, s.unmatched,
      s.position_rms, ls.rms, ls.points, ms);
  ++totals->frames;
  totals->truth += s.truth;
  totals->found += s.found;
  totals->wrong += s.Wrong();
  totals->worst_recall = std::min(totals->worst_recall, s.Recall());
  if (o.quiet) return;
  // A crop around junction m of the truth, named by the scene and m's label.
  auto crop = [&](const char* prefix, const bsls::simulator::PointLabel& m) {
    if (o.crops.empty()) return;
    char file[160];
    std::snprintf(file, sizeof file, "/%s%s_%s_%u_p%d_v%d.png", prefix,
                  std::string(bsls::simulator::ToString(kind)).c_str(),
                  std::string(bsls::pattern::ToString(side)).c_str(), seed, m.p, m.v);
    WriteCrop(o.crops + file, frame.image, r, m.position);
  };
  for (const auto& m : s.missed) {
    const bsls::simulator::TruthJunction* t = nullptr;
    for (size_t i = 0; i < truth.size(); ++i)
      if (truth[i].p == m.p && truth[i].v == m.v) t = records[i];
    crop("", m);
    std::printf("    missed p %2d v %3d at (%7.2f, %7.2f) %-13s%s\n", m.p, m.v, m.position.x,
                m.position.y, t ? std::string(bsls::pattern::ToString(t->kind)).c_str() : "",
                t ? Reason(*t, m.position, decoded, s.v_offset, o.size, o.size).c_str() : "");
  }
  for (const auto& m : s.wrong) {
    crop("wrong_", m);
    std::printf("    WRONG  p %2d v %3d at (%7.2f, %7.2f)\n", m.p, m.v, m.position.x, m.position.y);
  }
  if (o.extra) {
    // Decoded junctions with no truth junction within reach.
    for (const auto& d : decoded) {
      double best = 1e9;
      for (const auto& t : truth)
        best = std::min(best, std::hypot(t.position.x - d.position.x, t.position.y - d.position.y));
      if (best > reach)
        std::printf("    extra  p %2d q %3d at (%7.2f, %7.2f), nearest truth %.1f px\n", d.p, d.v,
                    d.position.x, d.position.y, best);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seeds" && i + 1 < argc) {
      o.seeds = std::atoi(argv[++i]);
    } else if (a == "--size" && i + 1 < argc) {
      o.size = std::atoi(argv[++i]);
    } else if (a == "--quiet") {
      o.quiet = true;
    } else if (a == "--extra") {
      o.extra = true;
    } else if (a == "--crops" && i + 1 < argc) {
      o.crops = argv[++i];
    } else if (a == "--chain" && i + 1 < argc &&
               (std::string(argv[i + 1]) == "tracks" || std::string(argv[i + 1]) == "skeleton")) {
      o.chain = std::string(argv[++i]) == "tracks" ? bsls::decoder::DecodeChain::kTracks
                                                   : bsls::decoder::DecodeChain::kSkeleton;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--seeds N] [--size PX] [--quiet] [--extra] [--crops DIR] "
                   "[--chain tracks|skeleton]\n",
                   argv[0]);
      return 2;
    }
  }
  if (o.seeds < 1 || o.size < 64 || o.size > 4096) {
    std::fprintf(stderr, "%s: --seeds must be >= 1 and --size within 64..4096\n", argv[0]);
    return 2;
  }
  Totals faces, objects;
  for (Side side : {Side::kLeft, Side::kRight})
    for (int seed = 1; seed <= o.seeds; ++seed)
      Report(SurfaceKind::kFace, side, static_cast<std::uint32_t>(seed), o, &faces);
  for (SurfaceKind kind : {SurfaceKind::kPlane, SurfaceKind::kRamp, SurfaceKind::kBall})
    for (Side side : {Side::kLeft, Side::kRight}) Report(kind, side, kObjectSeed, o, &objects);
  auto total = [](const char* what, const Totals& t) {
    std::printf("%s: %d frames, %d / %d found (%.2f %%), worst frame %.2f %%, %d wrong\n", what,
                t.frames, t.found, t.truth, t.truth ? 100.0 * t.found / t.truth : 0.0,
                100.0 * t.worst_recall, t.wrong);
  };
  total("faces", faces);
  total("objects", objects);
  return 0;
}
