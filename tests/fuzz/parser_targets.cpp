#include "parser_targets.h"

#include <sys/stat.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <utility>

#include "bsls/calibration/calibration_file.h"
#include "bsls/calibration/manifest.h"
#include "bsls/common/errors.h"
#include "bsls/config/bounded_yaml.h"
#include "bsls/io/frame_file.h"
#include "bsls/io/surface_file.h"
#include "bsls/simulator/mesh.h"
#include "bsls/testing/build_paths.h"
#include "daemon/bslsd/config.h"
#include "fuzz_input.h"
#include "grammars.h"
#include "processing/processd/config.h"

namespace bsls::fuzz {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Violation(const char* parser, const std::string& how) {
  throw ContractViolation(std::string(parser) + ": " + how);
}

// What `parse` returns, or nullopt where it refused with `Refusal`, the
// parser's own error; any other exception breaks the parser's contract.
template <typename Refusal, typename Parse>
auto ParsedOrRefused(const char* parser, const char* refusal, Parse parse)
    -> std::optional<decltype(parse())> {
  try {
    return parse();
  } catch (const Refusal&) {
    return std::nullopt;
  } catch (const std::exception& e) {
    Violation(parser, std::string("threw another error than ") + refusal + ": " + e.what());
  }
}

// The seeds of `target` that load as plain YAML within the default limits:
// the templates of its YAML grammar. Read once.
std::vector<std::string> YamlTemplates(const std::string& target) {
  std::vector<std::string> templates;
  std::error_code ec;
  std::vector<fs::path> files;
  for (fs::directory_iterator it(fs::path(SeedsDir()) / target, ec), end; !ec && it != end;
       it.increment(ec))
    files.push_back(it->path());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    std::ifstream in(file, std::ios::binary);
    std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    try {
      LoadBoundedYaml(text);
      templates.push_back(std::move(text));
    } catch (const YAML::Exception&) {
    }
  }
  return templates;
}

// Keys of every YAML file this project reads, for documents made from nothing.
const std::vector<std::string>& YamlKeys() {
  static const std::vector<std::string> keys = {"side",
                                                "target",
                                                "rows",
                                                "cols",
                                                "pitch_mm",
                                                "square_mm",
                                                "camera_views",
                                                "screen_views",
                                                "reference_views",
                                                "image",
                                                "z_mm",
                                                "pattern",
                                                "lines",
                                                "format",
                                                "format_version",
                                                "software_version",
                                                "width",
                                                "height",
                                                "camera",
                                                "intrinsics",
                                                "pose",
                                                "projector",
                                                "reference",
                                                "uncertainty",
                                                "listen",
                                                "unix_socket",
                                                "tcp",
                                                "socket_mode",
                                                "store",
                                                "root",
                                                "workers",
                                                "queue",
                                                "limits",
                                                "roles",
                                                "admin",
                                                "user",
                                                "log_level",
                                                "framestore",
                                                "backend",
                                                "slides",
                                                "max_frame_pixels",
                                                "drain_timeout_ms",
                                                "scratch_dir"};
  return keys;
}

// A private scratch folder for the targets that read files:
// $TMPDIR/bsls_parser_fuzz.<pid>, removed at a normal exit. libFuzzer ends
// its runs with _Exit (no atexit handlers), so each run first removes the
// folders of this user's earlier runs whose process is gone.
const fs::path& Scratch() {
  static const fs::path dir = [] {
    const char* base = std::getenv("TMPDIR");
    const fs::path root = base && *base ? base : "/tmp";
    constexpr std::string_view kPrefix = "bsls_parser_fuzz.";
    std::error_code ec;
    std::vector<fs::path> stale;
    for (fs::directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (name.rfind(kPrefix, 0) != 0) continue;
      const std::string pid = name.substr(kPrefix.size());
      struct stat st {};
      if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos ||
          ::lstat(it->path().c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::geteuid())
        continue;
      std::error_code gone;
      if (!fs::exists("/proc/" + pid, gone)) stale.push_back(it->path());
    }
    for (const fs::path& old : stale) fs::remove_all(old, ec);
    const fs::path d = root / (std::string(kPrefix) + std::to_string(::getpid()));
    fs::remove_all(d, ec);
    if (::mkdir(d.c_str(), 0700) != 0) std::abort();
    // The handler runs after `dir` is destroyed: it keeps its own copy, in
    // storage that has no destructor.
    static char removed_at_exit[4096];
    std::snprintf(removed_at_exit, sizeof removed_at_exit, "%s", d.c_str());
    std::atexit([] {
      std::error_code ignored;
      fs::remove_all(removed_at_exit, ignored);
    });
    return d;
  }();
  return dir;
}

// Writes `text` to `path` (whole, truncating).
void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// ------------------------------------------------------------------ YAML

// Walks a loaded tree without recursion; a violation when it is deeper or
// larger than `limits` allow (an alias that got through would show here as
// a node reached twice, a cycle as a walk that does not end).
void CheckTree(const YAML::Node& root, const YamlLimits& limits) {
  std::vector<std::pair<YAML::Node, int>> stack = {{root, 0}};
  std::size_t nodes = 0;
  while (!stack.empty()) {
    auto [node, depth] = stack.back();
    stack.pop_back();
    if (++nodes > limits.max_nodes)
      Violation("LoadBoundedYaml", "a loaded tree has more than max_nodes nodes");
    if (node.IsSequence() || node.IsMap()) {
      if (depth + 1 > limits.max_depth)
        Violation("LoadBoundedYaml", "a loaded tree is deeper than max_depth");
      if (node.IsSequence()) {
        for (const YAML::Node& child : node) stack.emplace_back(child, depth + 1);
      } else {
        for (const auto& entry : node) {
          stack.emplace_back(entry.first, depth + 1);
          stack.emplace_back(entry.second, depth + 1);
        }
      }
    }
  }
}

bool OneYaml(const std::string& text) {
  YamlLimits limits;
  YAML::Node root;
  try {
    root = LoadBoundedYaml(text, limits);
  } catch (const YAML::Exception&) {
    return false;  // the documented error
  }
  CheckTree(root, limits);
  return true;
}

// The raw bytes through `one`, then the same bytes read as a recipe by
// `grammar` (a structured input) through `one` again; whether the raw bytes
// were accepted (the seed replay's verdict).
template <typename One, typename Grammar>
bool RawThenGrammar(const std::uint8_t* data, std::size_t size, One one, Grammar grammar) {
  const bool accepted = one(std::string(reinterpret_cast<const char*>(data), size));
  FuzzInput in(data, size);
  one(grammar(in));
  return accepted;
}

bool RunYaml(const std::uint8_t* data, std::size_t size) {
  static const std::vector<std::string> templates = YamlTemplates("yaml");
  return RawThenGrammar(data, size, OneYaml,
                        [](FuzzInput& in) { return YamlFrom(in, templates, YamlKeys()); });
}

// ------------------------------------------------------------------ manifest

// The folder of the manifest target: every image a template names exists.
const fs::path& ManifestFolder() {
  static const fs::path dir = [] {
    const fs::path d = Scratch() / "manifest";
    fs::create_directories(d / "sub");
    for (const char* name : {"t0.png", "t1.png", "t2.png", "s0.png", "s1.png", "s2.png", "r0.png",
                             "r1.png", "sub/t3.png"})
      WriteFile(d / name, "");
    return d;
  }();
  return dir;
}

bool OneManifest(const std::string& text) {
  const fs::path path = ManifestFolder() / "manifest.yaml";
  WriteFile(path, text);
  const auto loaded = ParsedOrRefused<calibration::ManifestError>(
      "LoadManifest", "ManifestError", [&] { return calibration::LoadManifest(path); });
  if (!loaded) return false;
  const calibration::Manifest& m = *loaded;
  std::string why;
  if (!m.target.IsValid(&why)) Violation("LoadManifest", "accepted an invalid target: " + why);
  if (m.camera_views.size() < 2) Violation("LoadManifest", "accepted fewer than two camera views");
  std::set<double> z;
  for (const auto& v : m.camera_views) z.insert(v.z_mm);
  if (z.size() < 2) Violation("LoadManifest", "accepted camera views all at one z");
  if (m.screen_views.empty()) Violation("LoadManifest", "accepted no screen view");
  for (const auto* views : {&m.camera_views, &m.screen_views, &m.reference_views})
    for (const auto& v : *views) {
      if (!std::isfinite(v.z_mm)) Violation("LoadManifest", "accepted a non-finite z_mm");
      std::error_code ec;
      if (!fs::exists(v.image, ec))
        Violation("LoadManifest", "accepted an image that does not exist: " + v.image.string());
    }
  return true;
}

bool RunManifest(const std::uint8_t* data, std::size_t size) {
  static const std::vector<std::string> templates = YamlTemplates("manifest");
  return RawThenGrammar(data, size, OneManifest,
                        [](FuzzInput& in) { return YamlFrom(in, templates, YamlKeys()); });
}

// ------------------------------------------------------------------ calibration file

bool OneCalibration(const std::string& text) {
  const auto loaded = ParsedOrRefused<calibration::CalibrationFileError>(
      "CalibrationFromYaml", "CalibrationFileError",
      [&] { return calibration::CalibrationFromYaml(text, "fuzz.yaml"); });
  if (!loaded) return false;
  const calibration::CalibrationRecord& record = *loaded;
  const calibration::SideCalibration& c = record.calibration;
  if (record.format_version != calibration::kCalibrationFormatVersion)
    Violation("CalibrationFromYaml", "accepted another format version");
  if (c.width <= 0 || c.height <= 0)
    Violation("CalibrationFromYaml", "accepted an image size that is not positive");
  std::string why;
  if (!c.target.IsValid(&why))
    Violation("CalibrationFromYaml", "accepted an invalid target: " + why);
  // What was read writes back and reads back the same (the file is the
  // calibration's only record).
  const std::string again = calibration::CalibrationToYaml(c, record.software_version);
  try {
    const calibration::CalibrationRecord reread = calibration::CalibrationFromYaml(again, "again");
    if (calibration::CalibrationToYaml(reread.calibration, reread.software_version) != again)
      Violation("CalibrationFromYaml", "a loaded calibration does not read back the same");
  } catch (const calibration::CalibrationFileError& e) {
    Violation("CalibrationFromYaml",
              std::string("a loaded calibration, written again, is refused: ") + e.what());
  }
  return true;
}

bool RunCalibration(const std::uint8_t* data, std::size_t size) {
  static const std::vector<std::string> templates = YamlTemplates("calibration");
  return RawThenGrammar(data, size, OneCalibration,
                        [](FuzzInput& in) { return YamlFrom(in, templates, YamlKeys()); });
}

// ------------------------------------------------------------------ service configurations

// Up to two "a.b=value" overrides from the recipe (the command line's --set).
std::vector<std::string> Overrides(FuzzInput& in) {
  std::vector<std::string> overrides;
  const std::uint32_t n = in.Below(3);
  for (std::uint32_t i = 0; i < n; ++i) {
    std::string key = in.Pick(YamlKeys());
    if (in.Flip()) key = in.Pick(YamlKeys()) + "." + key;
    const std::string value =
        in.Flip()
            ? std::string(in.Pick({"1", "\"0666\"", "[a, b]", "{x: 1}", "&a [*a]", "", "~", "-1"}))
            : in.Bytes(16);
    overrides.push_back(key + "=" + value);
  }
  return overrides;
}

bool OneBslsdConfig(const std::string& text, const std::vector<std::string>& overrides) {
  const fs::path path = Scratch() / "bslsd.yaml";
  WriteFile(path, text);
  std::optional<Result<bslsd::Config>> config;
  try {
    config.emplace(bslsd::LoadConfig(path.string(), overrides));
  } catch (const std::exception& e) {
    Violation("bslsd::LoadConfig", std::string("threw instead of returning a status: ") + e.what());
  }
  if (!config->ok()) {
    if (config->status().message().empty())
      Violation("bslsd::LoadConfig", "refused a configuration without saying why");
    return false;
  }
  if (!bslsd::Validate(**config).ok())
    Violation("bslsd::LoadConfig", "returned a configuration that Validate refuses");
  // What --check-config prints loads back as the same configuration.
  const std::string dump = bslsd::Dump(**config);
  WriteFile(path, dump);
  const Result<bslsd::Config> again = bslsd::LoadConfig(path.string(), {});
  if (!again.ok())
    Violation("bslsd::LoadConfig", "its own Dump is refused: " + again.status().message());
  if (bslsd::Dump(*again) != dump)
    Violation("bslsd::LoadConfig", "its own Dump loads as another configuration");
  return true;
}

bool RunBslsdConfig(const std::uint8_t* data, std::size_t size) {
  const bool accepted = OneBslsdConfig(std::string(reinterpret_cast<const char*>(data), size), {});
  static const std::vector<std::string> templates = YamlTemplates("bslsd_config");
  FuzzInput in(data, size);
  const std::vector<std::string> overrides = Overrides(in);
  OneBslsdConfig(YamlFrom(in, templates, YamlKeys()), overrides);
  return accepted;
}

bool OneProcessdConfig(const std::string& text, const std::vector<std::string>& overrides) {
  const fs::path path = Scratch() / "processd.yaml";
  WriteFile(path, text);
  const auto loaded = ParsedOrRefused<processd::ConfigError>(
      "processd::LoadConfig", "ConfigError",
      [&] { return processd::LoadConfig(path.string(), overrides); });
  if (!loaded) return false;
  const processd::Config& config = *loaded;
  if (processd::Workers(config) < 1) Violation("processd::LoadConfig", "accepted no worker");
  if (config.max_frame_pixels < 512 * 512 || config.max_frame_pixels > 4096 * 4096)
    Violation("processd::LoadConfig", "accepted a pixel budget outside [512^2, 4096^2]");
  const std::string dump = processd::Dump(config);
  WriteFile(path, dump);
  try {
    if (processd::Dump(processd::LoadConfig(path.string(), {})) != dump)
      Violation("processd::LoadConfig", "its own Dump loads as another configuration");
  } catch (const processd::ConfigError& e) {
    Violation("processd::LoadConfig", std::string("its own Dump is refused: ") + e.what());
  }
  return true;
}

bool RunProcessdConfig(const std::uint8_t* data, std::size_t size) {
  const bool accepted =
      OneProcessdConfig(std::string(reinterpret_cast<const char*>(data), size), {});
  static const std::vector<std::string> templates = YamlTemplates("processd_config");
  FuzzInput in(data, size);
  const std::vector<std::string> overrides = Overrides(in);
  OneProcessdConfig(YamlFrom(in, templates, YamlKeys()), overrides);
  return accepted;
}

// ------------------------------------------------------------------ PLY

bool OnePly(const std::string& bytes) {
  const auto loaded = ParsedOrRefused<InputError>("DecodePly", "InputError",
                                                  [&] { return io::DecodePly(bytes, "fuzz.ply"); });
  if (!loaded) return false;
  const geometry::SurfaceMesh& mesh = *loaded;
  std::string why;
  if (!mesh.IsValid(&why)) Violation("DecodePly", "returned an invalid mesh: " + why);
  // Every vertex and every triangle of a fan takes at least a byte of the body.
  if (mesh.VertexCount() > bytes.size() || mesh.faces.size() > bytes.size())
    Violation("DecodePly", "returned more vertices or faces than the file has bytes");
  return true;
}

bool RunPly(const std::uint8_t* data, std::size_t size) {
  return RawThenGrammar(data, size, OnePly, [](FuzzInput& in) { return PlyFrom(in); });
}

// ------------------------------------------------------------------ OBJ

bool OneObj(const std::string& text) {
  const fs::path path = Scratch() / "mesh.obj";
  WriteFile(path, text);
  const auto loaded = ParsedOrRefused<simulator::MeshLoadError>(
      "LoadObj", "MeshLoadError", [&] { return simulator::LoadObj(path); });
  if (!loaded) return false;
  const simulator::IndexedMesh& mesh = *loaded;
  const auto n = static_cast<int>(mesh.vertices.size());
  for (const auto& t : mesh.triangles)
    for (const int i : t)
      if (i < 0 || i >= n) Violation("LoadObj", "returned a triangle naming no vertex");
  for (const auto& v : mesh.vertices)
    if (!v.allFinite()) Violation("LoadObj", "returned a non-finite vertex");
  return true;
}

bool RunObj(const std::uint8_t* data, std::size_t size) {
  return RawThenGrammar(data, size, OneObj, [](FuzzInput& in) { return ObjFrom(in); });
}

// ------------------------------------------------------------------ PNG frames

bool OnePng(const std::string& bytes) {
  const std::vector<unsigned char> buffer(bytes.begin(), bytes.end());
  const io::FrameLimits limits;  // what the services and the CLI read frames with
  const auto loaded = ParsedOrRefused<InputError>("DecodeGreyFrame", "InputError", [&] {
    return io::DecodeGreyFrame(buffer, "fuzz.png", nullptr, limits);
  });
  if (!loaded) return false;
  const cv::Mat& grey = *loaded;
  if (grey.type() != CV_8UC1 || !grey.isContinuous())
    Violation("DecodeGreyFrame", "returned another than a continuous 8-bit grey image");
  if (grey.cols < limits.min_side || grey.rows < limits.min_side || grey.cols > limits.max_side ||
      grey.rows > limits.max_side || static_cast<std::int64_t>(grey.total()) > limits.max_pixels)
    Violation("DecodeGreyFrame", "returned a frame outside its limits");
  return true;
}

bool RunPng(const std::uint8_t* data, std::size_t size) {
  return RawThenGrammar(data, size, OnePng, [](FuzzInput& in) { return PngFrom(in); });
}

// ------------------------------------------------------------------ JSON

// The product reads outside JSON only in the CLI (bsls evaluate's junction
// and truth files, bsls measure's reply), with nlohmann::json::parse: the
// same call, the same error.
bool OneJson(const std::string& text) {
  try {
    const nlohmann::json value = nlohmann::json::parse(text);
    (void)value.dump();
  } catch (const nlohmann::json::exception&) {
    return false;
  }
  return true;
}

bool RunJson(const std::uint8_t* data, std::size_t size) {
  return RawThenGrammar(data, size, OneJson, [](FuzzInput& in) { return JsonFrom(in); });
}

}  // namespace

const std::vector<ParserTarget>& ParserTargets() {
  static const std::vector<ParserTarget> targets = {
      {"yaml", "LoadBoundedYaml", &RunYaml},
      {"manifest", "calibration::LoadManifest", &RunManifest},
      {"calibration", "calibration::CalibrationFromYaml", &RunCalibration},
      {"bslsd_config", "bslsd::LoadConfig", &RunBslsdConfig},
      {"processd_config", "processd::LoadConfig", &RunProcessdConfig},
      {"ply", "io::DecodePly", &RunPly},
      {"obj", "simulator::LoadObj", &RunObj},
      {"png", "io::DecodeGreyFrame", &RunPng},
      {"json", "nlohmann::json::parse", &RunJson},
  };
  return targets;
}

const ParserTarget* FindParserTarget(std::string_view name) {
  for (const ParserTarget& t : ParserTargets())
    if (name == t.name) return &t;
  return nullptr;
}

std::string SeedsDir() { return bsls::testing::FuzzSeedsDir().string(); }

}  // namespace bsls::fuzz
