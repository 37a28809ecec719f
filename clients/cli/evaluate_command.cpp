// bsls evaluate: scores a decode (contracts section 5 JSON) against the
// ground truth `bsls simulate --truth` wrote for the same frame, or against
// an outside renderer's truth of the same layout (junctions with "q" for the
// slide row, lines with "samples" of [x, row, ...], as in
// shared/data/outside-corpus).
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "bsls/common/errors.h"
#include "bsls/simulator/evaluation.h"
#include "command.h"

namespace bsls::cli {
namespace {

struct EvaluateOptions {
  std::string junctions;
  std::string truth;
  double reach = 2.5;
  bool json = false;
};

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot be opened");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    // The parser's own message quotes the bytes it read, which may be binary.
    throw InputError(path + ": not valid JSON (error at byte " + std::to_string(e.byte) + ")");
  }
}

// Junctions and lines of a decode or a truth file. A junction's slide row
// is its "q" (a decode, an outside truth) or "v" (the simulator's truth); a
// line's centre points are its "points" or its "samples" (whose first two
// values are x and the row). `what` names the kind of file in errors.
void ReadLabels(const std::string& path, const char* what,
                std::vector<simulator::PointLabel>* junctions,
                std::vector<simulator::LinePoints>* lines) {
  const nlohmann::json j = ReadJson(path);
  try {
    for (const auto& k : j.at("junctions")) {
      const int row = k.contains("q") ? k.at("q").get<int>() : k.at("v").get<int>();
      junctions->push_back(
          {k.at("p").get<int>(), row, {k.at("x").get<double>(), k.at("y").get<double>()}});
    }
    for (const auto& l : j.at("lines")) {
      simulator::LinePoints line{l.at("p").get<int>(), {}};
      for (const auto& pt : l.contains("points") ? l.at("points") : l.at("samples"))
        line.points.emplace_back(pt.at(0).get<double>(), pt.at(1).get<double>());
      lines->push_back(std::move(line));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a " + what + " file: " + e.what());
  }
}

void RunEvaluate(const EvaluateOptions& o) {
  std::vector<simulator::PointLabel> decoded, truth;
  std::vector<simulator::LinePoints> decoded_lines, truth_lines;
  ReadLabels(o.junctions, "junctions", &decoded, &decoded_lines);
  ReadLabels(o.truth, "truth", &truth, &truth_lines);
  const simulator::LabelScore score = simulator::ScoreLabels(truth, decoded, o.reach);
  const simulator::LineScore lines = simulator::ScoreLines(truth_lines, decoded_lines);
  if (o.json) {
    const nlohmann::json out = {{"truth", score.truth},
                                {"found", score.found},
                                {"recall", score.Recall()},
                                {"right", score.Right()},
                                {"right_recall", score.RightRecall()},
                                {"wrong_p", score.wrong_p},
                                {"wrong_q", score.wrong_v},
                                {"unmatched", score.unmatched},
                                {"q_offset", score.v_offset},
                                {"junction_rms_px", score.position_rms},
                                {"line_points", lines.points},
                                {"line_rms_px", lines.rms}};
    std::cout << out.dump() << "\n";
    return;
  }
  std::printf(
      "junctions: %d of %d found (%.1f %%), %d wrong p, %d wrong q, %d not in the truth, "
      "position RMS %.3f px\nlines: %d points, centre RMS %.3f px\n",
      score.found, score.truth, 100.0 * score.Recall(), score.wrong_p, score.wrong_v,
      score.unmatched, score.position_rms, lines.points, lines.rms);
}

}  // namespace

void AddEvaluateCommand(CLI::App& app) {
  auto opts = std::make_shared<EvaluateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate", "Score decoded junctions and lines against a simulated frame's ground truth");
  cmd->add_option("JUNCTIONS", opts->junctions, "Output of bsls process (contracts JSON)")
      ->required();
  cmd->add_option("TRUTH", opts->truth, "Ground truth written by bsls simulate --truth")
      ->required();
  cmd->add_option("--reach", opts->reach, "Largest distance (px) of a match (default 2.5)")
      ->check(CLI::Range(0.1, 50.0));
  cmd->add_flag("--json", opts->json, "Print the scores as one JSON object");
  cmd->callback([opts] { RunEvaluate(*opts); });
}

}  // namespace bsls::cli
