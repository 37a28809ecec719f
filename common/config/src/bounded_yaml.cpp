#include "bsls/config/bounded_yaml.h"

#include <yaml-cpp/eventhandler.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace bsls {
namespace {

// Counts nodes and depth on the parser's events; throws at the first that
// breaks a limit.
class ShapeCheck : public YAML::EventHandler {
 public:
  explicit ShapeCheck(const YamlLimits& limits) : limits_(limits) {}

  void OnDocumentStart(const YAML::Mark&) override { depth_ = 0; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { Count(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    throw YAML::ParserException(mark, "aliases (*name) are not accepted");
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Count(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnSequenceEnd() override { --depth_; }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Open(mark);
  }
  void OnMapEnd() override { --depth_; }

 private:
  void Count(const YAML::Mark& mark) {
    if (++nodes_ > limits_.max_nodes)
      throw YAML::ParserException(mark,
                                  "more than " + std::to_string(limits_.max_nodes) + " nodes");
  }
  void Open(const YAML::Mark& mark) {
    Count(mark);
    if (++depth_ > limits_.max_depth)
      throw YAML::ParserException(
          mark, "nested deeper than " + std::to_string(limits_.max_depth) + " levels");
  }

  const YamlLimits& limits_;
  std::size_t nodes_ = 0;
  int depth_ = 0;
};

}  // namespace

YAML::Node LoadBoundedYaml(const std::string& text, const YamlLimits& limits) {
  {
    std::istringstream in(text);
    YAML::Parser parser(in);
    ShapeCheck check(limits);
    while (parser.HandleNextDocument(check)) {
    }
  }
  return YAML::Load(text);
}

YAML::Node LoadBoundedYamlFile(const std::string& path, const YamlLimits& limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw YAML::BadFile(path);
  if (size > limits.max_bytes)
    throw YAML::ParserException(YAML::Mark::null_mark(), "the file is " + std::to_string(size) +
                                                             " bytes, more than " +
                                                             std::to_string(limits.max_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw YAML::BadFile(path);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return LoadBoundedYaml(text, limits);
}

}  // namespace bsls
