// Decoder report on randomised scenes (bsls/simulator/random_scene.h): N
// frames of the tuning or the held-out seed set, each rendered, decoded with
// the default decoder (bsls::decoder::Decode, default DecodeParams) and scored
// against its ground truth (simulator::ScoreLabels, reach 2.5 px at every
// image size). Tune on `--set tuning`; report `--set heldout` (docs/heldout.md).
//
// Per frame one line: seed, object, side, size, target pitch, the decoder's
// measured pitch, lit and visible junctions, recall (right labels / truth),
// wrong p, wrong q, unmatched decoded junctions, render and decode times. A
// frame the decoder refuses is marked "refused" and scored as recall 0;
// whether it had to refuse follows from the truth: line 0 counts as visible
// when at least kLineZeroJunctions of its junctions are (contracts section 2:
// an image without its reference line must be refused, not guessed).
// Then totals per object, per image-size band, per pitch band and per
// tolerance class, and the worst frames with every drawn parameter.
//
//   heldout_report [--set tuning|heldout] [--count N] [--first I] [--worst K]
//                  [--json FILE] [--images DIR] [--cache DIR] [--quiet]
//     --count  frames (default 200); --first  index of the first seed in the
//     set (default 0); --worst  frames listed in full (default 10); --json
//     per-frame figures and draws as JSON; --images  write each frame to
//     DIR/<seed>.png; --cache  keep each rendered frame and its visible truth in
//     DIR (<seed>.png, <seed>.truth) and read them back on later runs (the
//     render is 99 % of a run; the drawing code must not have changed);
//     --quiet  totals only; --geometry  decode with a calibration of the
//     drawn rig as an exact session would give it
//     (reconstruction::CalibrationOfKnownDevices, screens at 0 and 150 mm):
//     the track chain then places the parts not joined to line 0 and checks
//     line 0's own by the geometry (reconstruction/island_placement.h);
//     --wrong  lists every wrongly labelled junction before its frame's line.
// Exit status 0 when every frame ran, 2 on bad arguments, 1 on an error.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/reconstruction/island_placement.h"
#include "bsls/simulator/evaluation.h"
#include "bsls/simulator/random_scene.h"
#include "bsls/simulator/renderer.h"

namespace {

namespace sim = bsls::simulator;

constexpr double kMatchReach = 2.5;     // px, as tests/decoder and the outside corpus
constexpr int kLineZeroJunctions = 3;   // visible junctions on line 0 that make it visible
constexpr double kBasePlaneBand = 0.5;  // mm: junctions this close to z = 0 are on the base plane

struct Options {
  sim::SeedSet set = sim::SeedSet::kHeldOut;
  int count = 200;
  int first = 0;
  int worst = 10;
  std::string json;
  std::string images;  // folder for the rendered frames; empty: none
  // Folder of rendered frames and their visible truth, kept between runs
  // (a frame is rendered once, then read back); empty: none.
  std::string cache;
  bool quiet = false;
  bool geometry = false;
  bool list_wrong = false;
};

struct FrameResult {
  sim::RandomSceneDraw draw;
  bool refused = false;
  std::string refusal;
  bool line_zero_visible = false;
  double measured_pitch = 0.0;  // the decoder's, px (0: none)
  sim::LabelScore score;
  sim::LabelScore object, base;  // the truth on the object, on the base plane (unmatched: n/a)
  int right = 0;                 // found with the right label
  double render_ms = 0.0, decode_ms = 0.0;

  double Recall() const { return score.truth ? static_cast<double>(right) / score.truth : 0.0; }
  // Right labels among a part's truth.
  static int Right(const sim::LabelScore& s) { return s.found - s.Wrong(); }
};

struct Totals {
  int frames = 0, truth = 0, right = 0, wrong_p = 0, wrong_q = 0, unmatched = 0;
  int object_truth = 0, object_right = 0, base_truth = 0, base_right = 0;
  int refused = 0, refused_rightly = 0, labelled_without_line_zero = 0, frames_with_wrong_p = 0;
  double sum_recall = 0.0, worst_recall = 1.0;

  void Add(const FrameResult& f) {
    ++frames;
    truth += f.score.truth;
    right += f.right;
    object_truth += f.object.truth;
    object_right += FrameResult::Right(f.object);
    base_truth += f.base.truth;
    base_right += FrameResult::Right(f.base);
    wrong_p += f.score.wrong_p;
    wrong_q += f.score.wrong_v;
    unmatched += f.score.unmatched;
    frames_with_wrong_p += f.score.wrong_p > 0;
    if (f.refused) {
      ++refused;
      refused_rightly += !f.line_zero_visible;
    } else if (!f.line_zero_visible) {
      ++labelled_without_line_zero;
    }
    sum_recall += f.Recall();
    worst_recall = std::min(worst_recall, f.Recall());
  }
};

void PrintTotalsHeader() {
  std::printf("%-16s %6s %7s %8s %8s %7s %8s %8s %7s %9s %8s %9s %9s\n", "group", "frames", "truth",
              "recall", "mean", "worst", "object", "base", "wrong p", "(frames)", "wrong q",
              "unmatched", "refused");
}

void PrintTotals(const std::string& name, const Totals& t) {
  if (t.frames == 0) return;
  auto percent = [](int part, int whole) { return whole ? 100.0 * part / whole : 0.0; };
  std::printf("%-16s %6d %7d %7.2f%% %7.2f%% %6.2f%% %7.2f%% %7.2f%% %7d %9d %8d %9d %5d (%d)\n",
              name.c_str(), t.frames, t.truth, percent(t.right, t.truth),
              100.0 * t.sum_recall / t.frames, 100.0 * t.worst_recall,
              percent(t.object_right, t.object_truth), percent(t.base_right, t.base_truth),
              t.wrong_p, t.frames_with_wrong_p, t.wrong_q, t.unmatched, t.refused,
              t.refused_rightly);
}

std::string SizeBand(const sim::RandomSceneDraw& d) {
  const int size = std::max(d.width, d.height);
  if (size < 724) return "size 512-723";
  if (size < 1024) return "size 724-1023";
  if (size < 1448) return "size 1024-1447";
  return "size 1448-2048";
}

std::string PitchBand(const sim::RandomSceneDraw& d) {
  if (d.stripe_pitch_px < 12.0) return "pitch 8-12";
  if (d.stripe_pitch_px < 20.0) return "pitch 12-20";
  if (d.stripe_pitch_px < 32.0) return "pitch 20-32";
  return "pitch 32-64";
}

// The visible truth junctions: label, image point and world z.
struct VisibleTruth {
  sim::PointLabel label;
  double z = 0.0;
};

// The frame of `seed` and its visible truth: rendered, or read from the
// cache folder when it holds them (written there after rendering).
cv::Mat FrameOf(std::uint32_t seed, const sim::RandomScene& random, const Options& o,
                std::vector<VisibleTruth>* truth) {
  const std::string stem = o.cache.empty() ? "" : o.cache + "/" + std::to_string(seed);
  if (!stem.empty() && std::filesystem::exists(stem + ".png")) {
    cv::Mat image = cv::imread(stem + ".png", cv::IMREAD_UNCHANGED);
    std::ifstream in(stem + ".truth");
    if (!image.empty() && in) {
      VisibleTruth t;
      while (in >> t.label.p >> t.label.v >> t.label.position.x >> t.label.position.y >> t.z)
        truth->push_back(t);
      if (in.eof()) return image;
      truth->clear();
    }
  }
  sim::Frame frame = sim::Renderer(random.scene, random.render).Render();
  for (const sim::TruthJunction& j : frame.truth.junctions)
    if (j.visible) truth->push_back({{j.p, j.v, {j.image.x(), j.image.y()}}, j.world.z()});
  if (!stem.empty()) {
    std::ofstream out(stem + ".truth");
    out.precision(17);
    for (const VisibleTruth& t : *truth)
      out << t.label.p << ' ' << t.label.v << ' ' << t.label.position.x << ' ' << t.label.position.y
          << ' ' << t.z << '\n';
    if (!out || !cv::imwrite(stem + ".png", frame.image))
      throw std::runtime_error("could not write " + stem + ".png / .truth");
  }
  return frame.image;
}

FrameResult RunFrame(std::uint32_t seed, const Options& o) {
  FrameResult f;
  const auto t0 = std::chrono::steady_clock::now();
  const sim::RandomScene random = sim::MakeRandomScene(seed);
  f.draw = random.draw;
  std::vector<VisibleTruth> visible;
  const cv::Mat image = FrameOf(seed, random, o, &visible);
  const auto t1 = std::chrono::steady_clock::now();
  if (!o.images.empty()) {
    const std::string path = o.images + "/" + std::to_string(seed) + ".png";
    if (!cv::imwrite(path, image)) throw std::runtime_error("could not write " + path);
  }
  bsls::decoder::DecodeParams params;
  if (o.geometry) {
    const sim::Scene& scene = random.scene;
    params.geometry = bsls::reconstruction::LabelGeometryOfCalibration(
        bsls::reconstruction::CalibrationOfKnownDevices(scene.side, scene.camera, scene.projector,
                                                        scene.pattern, image.cols, image.rows));
  }
  const bsls::decoder::DecodeResult r = bsls::decoder::Decode(image, random.scene.side, params);
  const auto t2 = std::chrono::steady_clock::now();
  f.render_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  f.decode_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  f.measured_pitch = r.pitch;
  std::vector<sim::PointLabel> truth;
  for (const VisibleTruth& t : visible) truth.push_back(t.label);
  f.line_zero_visible = std::count_if(truth.begin(), truth.end(),
                                      [](const auto& j) { return j.p == 0; }) >= kLineZeroJunctions;
  std::vector<sim::PointLabel> decoded;
  if (r.ok) {
    for (const auto& j : r.junctions) decoded.push_back({j.p, j.q, j.position});
  } else {
    f.refused = true;
    f.refusal = r.error;
  }
  f.score = sim::ScoreLabels(truth, decoded, kMatchReach);
  // Recall on the object and on the base plane around it, apart.
  std::vector<sim::PointLabel> on_object, on_base;
  for (const VisibleTruth& t : visible) {
    const bool base = f.draw.object != sim::RandomObject::kPlane && std::abs(t.z) < kBasePlaneBand;
    (base ? on_base : on_object).push_back(t.label);
  }
  for (const auto& [part, score] :
       {std::pair{&on_object, &f.object}, std::pair{&on_base, &f.base}}) {
    *score = sim::ScoreLabels(*part, decoded, kMatchReach);
  }
  f.right = f.score.found - f.score.Wrong();
  if (o.list_wrong)
    for (const sim::PointLabel& w : f.score.wrong) {
      // The decoded junction nearest the truth, as the scoring matched it.
      const sim::PointLabel* near = nullptr;
      for (const sim::PointLabel& d : decoded)
        if (cv::norm(d.position - w.position) <= kMatchReach &&
            (!near || cv::norm(d.position - w.position) < cv::norm(near->position - w.position)))
          near = &d;
      if (!near) continue;
      std::printf(
          "  seed %u wrong label at (%.1f, %.1f): decoded p %d q %d, truth p %d v %d (rows offset "
          "%d)\n",
          seed, w.position.x, w.position.y, near->p, near->v, w.p, w.v, f.score.v_offset);
    }
  return f;
}

void PrintFrame(const FrameResult& f) {
  const sim::RandomSceneDraw& d = f.draw;
  auto percent = [](const sim::LabelScore& s) {
    return s.truth ? 100.0 * FrameResult::Right(s) / s.truth : 0.0;
  };
  std::printf(
      "%6u %-8s %-5s %4dx%-4d pitch %5.1f/%5.1f  truth %4d recall %6.2f%% (object %6.2f%%"
      " base %6.2f%%)  wrong p %3d q %3d  unmatched %3d%s%s  %6.0f + %5.0f ms\n",
      d.seed, std::string(sim::ToString(d.object)).c_str(),
      std::string(bsls::pattern::ToString(d.side)).c_str(), d.width, d.height, d.stripe_pitch_px,
      f.measured_pitch, f.score.truth, 100.0 * f.Recall(), percent(f.object), percent(f.base),
      f.score.wrong_p, f.score.wrong_v, f.score.unmatched, f.refused ? "  REFUSED" : "",
      f.line_zero_visible ? "" : "  (line 0 hidden)", f.render_ms, f.decode_ms);
}

nlohmann::json FrameJson(const FrameResult& f) {
  return {{"draw", sim::ToJson(f.draw)},
          {"refused", f.refused},
          {"refusal", f.refusal},
          {"line_zero_visible", f.line_zero_visible},
          {"measured_pitch_px", f.measured_pitch},
          {"truth", f.score.truth},
          {"right", f.right},
          {"recall", f.Recall()},
          {"wrong_p", f.score.wrong_p},
          {"wrong_q", f.score.wrong_v},
          {"unmatched", f.score.unmatched},
          {"position_rms_px", f.score.position_rms},
          {"render_ms", f.render_ms},
          {"decode_ms", f.decode_ms}};
}

int Usage(const char* argv0) {
  std::fprintf(stderr,
               "usage: %s [--set tuning|heldout] [--count N] [--first I] [--worst K] "
               "[--json FILE] [--images DIR] [--cache DIR] [--quiet] [--geometry] [--wrong]\n",
               argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--set" && has_value) {
      const std::string v = argv[++i];
      if (v == "tuning")
        o.set = sim::SeedSet::kTuning;
      else if (v == "heldout")
        o.set = sim::SeedSet::kHeldOut;
      else
        return Usage(argv[0]);
    } else if (a == "--count" && has_value) {
      o.count = std::atoi(argv[++i]);
    } else if (a == "--first" && has_value) {
      o.first = std::atoi(argv[++i]);
    } else if (a == "--worst" && has_value) {
      o.worst = std::atoi(argv[++i]);
    } else if (a == "--json" && has_value) {
      o.json = argv[++i];
    } else if (a == "--images" && has_value) {
      o.images = argv[++i];
    } else if (a == "--cache" && has_value) {
      o.cache = argv[++i];
    } else if (a == "--quiet") {
      o.quiet = true;
    } else if (a == "--geometry") {
      o.geometry = true;
    } else if (a == "--wrong") {
      o.list_wrong = true;
    } else {
      return Usage(argv[0]);
    }
  }
  if (o.count < 1 || o.first < 0 || o.worst < 0) {
    std::fprintf(stderr, "%s: --count must be >= 1, --first and --worst >= 0\n", argv[0]);
    return 2;
  }
  std::vector<FrameResult> frames;
  const auto start = std::chrono::steady_clock::now();
  try {
    const std::uint32_t first_seed = sim::SeedOf(o.set, o.first);
    const std::uint32_t last_seed = sim::SeedOf(o.set, o.first + o.count - 1);
    std::printf("heldout_report: %s set, seeds %u..%u, default decoder%s, reach %.1f px\n",
                std::string(sim::ToString(o.set)).c_str(), first_seed, last_seed,
                o.geometry ? " with the rig's geometry" : "", kMatchReach);
    if (!o.quiet)
      std::printf("%6s %-8s %-5s %-9s %s\n", "seed", "object", "side", "size",
                  "pitch target/measured ...");
    for (int i = 0; i < o.count; ++i) {
      frames.push_back(RunFrame(sim::SeedOf(o.set, o.first + i), o));
      if (!o.quiet) PrintFrame(frames.back());
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  Totals all;
  std::map<std::string, Totals> by_object, by_size, by_pitch, by_class;
  double render_ms = 0.0, decode_ms = 0.0;
  for (const FrameResult& f : frames) {
    all.Add(f);
    by_object[std::string(sim::ToString(f.draw.object))].Add(f);
    by_size[SizeBand(f.draw)].Add(f);
    by_pitch[PitchBand(f.draw)].Add(f);
    by_class[f.draw.beyond_tolerance ? "beyond tol." : "within tol."].Add(f);
    render_ms += f.render_ms;
    decode_ms += f.decode_ms;
  }
  std::printf(
      "\nrecall = right labels / lit and visible junctions (refused frames count 0); "
      "mean = mean of the frames' recalls;\nobject / base = recall on the object's "
      "junctions / on the base plane's (|z| < %.1f mm; plane frames: all object);\n"
      "refused (n) = frames the decoder refused (n of them without a visible line 0, "
      "rightly)\n",
      kBasePlaneBand);
  PrintTotalsHeader();
  PrintTotals("all", all);
  for (const auto* group : {&by_object, &by_size, &by_pitch, &by_class})
    for (const auto& [name, totals] : *group) PrintTotals(name, totals);
  std::printf("frames labelled although line 0 was hidden: %d\n", all.labelled_without_line_zero);
  std::printf("time: %.0f s (render %.0f s, decode %.1f s, %.1f ms a frame)\n", seconds,
              render_ms / 1000.0, decode_ms / 1000.0, decode_ms / frames.size());

  // Worst frames: every one with a wrong p first, then the lowest recall.
  std::vector<const FrameResult*> order;
  for (const FrameResult& f : frames) order.push_back(&f);
  std::stable_sort(order.begin(), order.end(), [](const FrameResult* a, const FrameResult* b) {
    if ((a->score.wrong_p > 0) != (b->score.wrong_p > 0)) return a->score.wrong_p > 0;
    return a->Recall() < b->Recall();
  });
  if (o.worst > 0) std::printf("\nworst frames (wrong p first, then lowest recall):\n");
  for (int i = 0; i < o.worst && i < static_cast<int>(order.size()); ++i) {
    const FrameResult& f = *order[i];
    std::printf("  recall %6.2f%% wrong p %d q %d%s%s\n    %s\n", 100.0 * f.Recall(),
                f.score.wrong_p, f.score.wrong_v, f.refused ? " refused: " : "", f.refusal.c_str(),
                f.draw.Describe().c_str());
  }
  if (!o.json.empty()) {
    nlohmann::json out = nlohmann::json::array();
    for (const FrameResult& f : frames) out.push_back(FrameJson(f));
    std::ofstream file(o.json);
    file << out.dump(1) << "\n";
    if (!file) {
      std::fprintf(stderr, "%s: could not write %s\n", argv[0], o.json.c_str());
      return 1;
    }
  }
  return 0;
}
