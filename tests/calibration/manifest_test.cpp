#include "bsls/calibration/manifest.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace bsls::calibration {
namespace {

namespace fs = std::filesystem;

class ManifestFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("manifest_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    for (const char* name : {"t0.png", "t10.png", "s0.png", "c0.png"})
      std::ofstream(dir_ / name) << "x";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& text) {
    const fs::path p = dir_ / "manifest.yaml";
    std::ofstream(p) << text;
    return p;
  }
  std::string Error(const std::string& text) {
    try {
      LoadManifest(Write(text));
    } catch (const ManifestError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

constexpr const char* kGood = R"(side: right
target: {rows: 8, cols: 8, pitch_mm: 6.5, square_mm: 4.0}
camera_views:
  - {image: t0.png, z_mm: 0}
  - {image: t10.png, z_mm: 10}
screen_views:
  - {image: s0.png, z_mm: 0}
reference_views:
  - {image: c0.png, z_mm: 0}
pattern: {lines: 20, rows: 24}
)";

TEST_F(ManifestFiles, ContractsExampleLoadsWithResolvedPaths) {
  const Manifest m = LoadManifest(Write(kGood));
  EXPECT_EQ(m.side, pattern::Side::kRight);
  ASSERT_EQ(m.camera_views.size(), 2u);
  EXPECT_EQ(m.camera_views[1].image, dir_ / "t10.png");
  EXPECT_DOUBLE_EQ(m.camera_views[1].z_mm, 10.0);
  EXPECT_EQ(m.screen_views.size(), 1u);
  EXPECT_EQ(m.reference_views.size(), 1u);
  EXPECT_EQ(m.pattern.lines, 20);
  EXPECT_EQ(m.sha256.size(), 64u);
  EXPECT_EQ(m.target.SquareCentre(2, 3, 10.0), Eigen::Vector3d(19.5, -13.0, 10.0));
}

TEST_F(ManifestFiles, WrittenManifestReadsBackTheSame) {
  const Manifest m = LoadManifest(Write(kGood));
  const fs::path again = dir_ / "again.yaml";
  std::ofstream(again) << ManifestToYaml(m, dir_);
  const Manifest n = LoadManifest(again);
  EXPECT_EQ(n.side, m.side);
  ASSERT_EQ(n.camera_views.size(), m.camera_views.size());
  for (size_t i = 0; i < n.camera_views.size(); ++i) {
    EXPECT_EQ(n.camera_views[i].image, m.camera_views[i].image);
    EXPECT_EQ(n.camera_views[i].z_mm, m.camera_views[i].z_mm);
  }
  EXPECT_EQ(n.reference_views.size(), 1u);
}

TEST_F(ManifestFiles, HashFollowsTheBytes) {
  const std::string a = LoadManifest(Write(kGood)).sha256;
  const std::string b = LoadManifest(Write(std::string(kGood) + "# edited\n")).sha256;
  EXPECT_NE(a, b);
}

TEST_F(ManifestFiles, BadManifestsSayWhy) {
  std::string text = kGood;
  EXPECT_NE(Error("side: up\n").find("side must be left or right"), std::string::npos);
  EXPECT_NE(Error("[1, 2]\n").find("not a manifest"), std::string::npos);
  EXPECT_NE(Error("side: left\ntarget: {rows: 8\n").find("not valid YAML"), std::string::npos);
  std::string missing = text;
  missing.replace(missing.find("t10.png"), 7, "gone.png");
  EXPECT_NE(Error(missing).find("gone.png does not exist"), std::string::npos);
  std::string flat = text;
  flat.replace(flat.find("z_mm: 10"), 8, "z_mm: 0");
  EXPECT_NE(Error(flat).find("two distinct z_mm"), std::string::npos);
  std::string square = text;
  square.replace(square.find("square_mm: 4.0"), 14, "square_mm: 7.0");
  EXPECT_NE(Error(square).find("square_mm < pitch_mm"), std::string::npos);
  std::string no_screen = text.substr(0, text.find("screen_views"));
  EXPECT_NE(Error(no_screen).find("'screen_views'"), std::string::npos);
  const std::string e = Error("side: left\n");
  EXPECT_NE(e.find("manifest.yaml"), std::string::npos) << e;
}

// Found by the manifest fuzz target (issue 26): a field that should be a
// mapping but is a scalar or a list threw yaml-cpp's BadSubscript ("operator[]
// call on a scalar"), which bsls-processd answered with INTERNAL.
TEST_F(ManifestFiles, ScalarsWhereMappingsBelongSayWhy) {
  std::string text = kGood;
  std::string target = text;
  target.replace(target.find("{rows: 8, cols: 8, pitch_mm: 6.5, square_mm: 4.0}"), 48, "5");
  EXPECT_NE(Error(target).find("target: expected a mapping with 'rows'"), std::string::npos)
      << Error(target);
  std::string view = text;
  view.replace(view.find("{image: t0.png, z_mm: 0}"), 24, "t0.png");
  EXPECT_NE(Error(view).find("camera_views[0]: expected a mapping with 'image'"), std::string::npos)
      << Error(view);
  std::string pattern = text;
  pattern.replace(pattern.find("{lines: 20, rows: 24}"), 21, "[20, 24]");
  EXPECT_NE(Error(pattern).find("pattern: expected a mapping with 'lines'"), std::string::npos)
      << Error(pattern);
}

TEST(Manifest, MissingFileIsNamed) {
  try {
    LoadManifest("/nonexistent/session/manifest.yaml");
    FAIL();
  } catch (const ManifestError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/session/manifest.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace bsls::calibration
