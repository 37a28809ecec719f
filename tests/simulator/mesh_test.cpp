#include "bsls/simulator/mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <utility>

#include "bsls/simulator/scene.h"
#include "bsls/testing/build_paths.h"

namespace bsls::simulator {
namespace {

constexpr double kDistanceTolerance = 1e-9;  // mm, BVH vs brute force
constexpr double kNormalTolerance = 1e-9;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
const std::filesystem::path kDataDir = bsls::testing::TestDataDir();

// Writes `content` to a fresh file in the test temp directory.
std::filesystem::path WriteTemp(const std::string& name, const std::string& content) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / name;
  std::ofstream(path) << content;
  return path;
}

// The message of the MeshLoadError `load` throws, or "" when it throws none.
template <typename Load>
std::string LoadErrorOf(Load load) {
  try {
    load();
  } catch (const MeshLoadError& e) {
    return e.what();
  }
  return "";
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

IndexedMesh Octahedron() {
  IndexedMesh mesh;
  mesh.vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                    {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return mesh;
}

TEST(LoadObj, ReadsTheBundledFace) {
  const IndexedMesh mesh = LoadObj(kDataDir / "canonical_face_model.obj");
  EXPECT_EQ(mesh.vertices.size(), 468u);
  EXPECT_EQ(mesh.triangles.size(), 898u);
  std::string error;
  EXPECT_TRUE(mesh.IsValid(&error)) << error;
}

TEST(LoadObj, MissingFileNamesTheFile) {
  const std::filesystem::path path = kDataDir / "no_such_face.obj";
  const std::string message = LoadErrorOf([&] { LoadObj(path); });
  EXPECT_TRUE(Contains(message, path.string())) << message;
  EXPECT_TRUE(Contains(message, "no such file")) << message;
}

TEST(LoadObj, CorruptFilesNameTheFileLineAndReason) {
  const auto bad_number = WriteTemp("bad_number.obj", "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n");
  std::string message = LoadErrorOf([&] { LoadObj(bad_number); });
  EXPECT_TRUE(Contains(message, bad_number.string())) << message;
  EXPECT_TRUE(Contains(message, "line 3")) << message;
  EXPECT_TRUE(Contains(message, "not a finite number")) << message;

  const auto bad_index = WriteTemp("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  message = LoadErrorOf([&] { LoadObj(bad_index); });
  EXPECT_TRUE(Contains(message, "line 4")) << message;
  EXPECT_TRUE(Contains(message, "vertex 4 of 3")) << message;

  const auto no_faces = WriteTemp("no_faces.obj", "# only vertices\nv 0 0 0\n");
  message = LoadErrorOf([&] { LoadObj(no_faces); });
  EXPECT_TRUE(Contains(message, "no faces")) << message;

  const auto binary = WriteTemp("binary.obj",
                                "\x7f"
                                "ELF\x01\x02 v\nf 1 2\n");
  message = LoadErrorOf([&] { LoadObj(binary); });
  EXPECT_TRUE(Contains(message, binary.string())) << message;
}

TEST(LoadObj, AcceptsSlashesNegativeIndicesAndPolygons) {
  const auto path = WriteTemp("quad.obj",
                              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\n"
                              "f 1/1/1 2//1 3/1 -1\n");
  const IndexedMesh mesh = LoadObj(path);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[1], (std::array<int, 3>{0, 2, 3}));
}

TEST(LoadMeshJson, ReadsTheBundledBunny) {
  const IndexedMesh mesh = LoadMeshJson(kDataDir / "stanford_bunny.json");
  EXPECT_EQ(mesh.vertices.size(), 1839u);
  EXPECT_EQ(mesh.triangles.size(), 3674u);
}

TEST(LoadMeshJson, CorruptFilesNameTheFileAndReason) {
  const auto not_json = WriteTemp("not_json.json", "{\"positions\": [[0, 0, 0]");
  std::string message = LoadErrorOf([&] { LoadMeshJson(not_json); });
  EXPECT_TRUE(Contains(message, not_json.string())) << message;
  EXPECT_TRUE(Contains(message, "not valid JSON")) << message;

  const auto bad_cell =
      WriteTemp("bad_cell.json", R"({"positions": [[0,0,0],[1,0,0],[0,1,0]], "cells": [[0,1,3]]})");
  message = LoadErrorOf([&] { LoadMeshJson(bad_cell); });
  EXPECT_TRUE(Contains(message, "cells[0] refers to vertex 3 of 3")) << message;

  message = LoadErrorOf([&] { LoadMeshJson(kDataDir / "missing.json"); });
  EXPECT_TRUE(Contains(message, "missing.json: no such file")) << message;
}

TEST(LoopSubdivide, CountsFollowEulerAndPlanesStayPlanar) {
  IndexedMesh square;
  square.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  const IndexedMesh once = LoopSubdivide(square, 1);
  EXPECT_EQ(once.vertices.size(), 4u + 5u);  // V + E
  EXPECT_EQ(once.triangles.size(), 8u);
  const IndexedMesh twice = LoopSubdivide(square, 2);
  EXPECT_EQ(twice.triangles.size(), 32u);
  for (const auto& v : twice.vertices) EXPECT_EQ(v.z(), 0.0);
  std::string error;
  EXPECT_TRUE(twice.IsValid(&error)) << error;
}

TEST(LoopSubdivide, SmoothsAnOctahedron) {
  // Largest angle (rad) between the normals of two triangles sharing an edge.
  auto max_crease = [](const IndexedMesh& mesh) {
    std::map<std::pair<int, int>, std::vector<Eigen::Vector3d>> normals_by_edge;
    for (const auto& t : mesh.triangles) {
      const Eigen::Vector3d n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                    .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                                    .normalized();
      for (int k = 0; k < 3; ++k) normals_by_edge[std::minmax(t[k], t[(k + 1) % 3])].push_back(n);
    }
    double worst = 0.0;
    for (const auto& [edge, normals] : normals_by_edge)
      if (normals.size() == 2)
        worst = std::max(worst, std::acos(std::clamp(normals[0].dot(normals[1]), -1.0, 1.0)));
    return worst;
  };
  const IndexedMesh octahedron = Octahedron();
  const IndexedMesh once = LoopSubdivide(octahedron, 1);
  const IndexedMesh thrice = LoopSubdivide(octahedron, 3);
  EXPECT_EQ(thrice.triangles.size(), 8u * 64u);
  // Each level shrinks the creases between neighbouring facets (slowest at
  // the octahedron's valence-4 vertices).
  EXPECT_LT(max_crease(once), 0.7 * max_crease(octahedron));
  EXPECT_LT(max_crease(thrice), 0.5 * max_crease(once));
  // Outward normals stay outward.
  const auto normals = VertexNormals(thrice);
  for (size_t i = 0; i < thrice.vertices.size(); ++i)
    EXPECT_GT(normals[i].dot(thrice.vertices[i]), 0.0) << i;
}

class FaceMeshBvh : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    FaceModelParams params;
    params.obj_path = kDataDir / "canonical_face_model.obj";
    face_ = new MeshSurface(LoadFaceMesh(params), "face");
  }
  static void TearDownTestSuite() {
    delete face_;
    face_ = nullptr;
  }
  static MeshSurface* face_;
};
MeshSurface* FaceMeshBvh::face_ = nullptr;

TEST_F(FaceMeshBvh, EqualsBruteForceOnRandomRays) {
  const Eigen::AlignedBox3d box = face_->mesh().Bounds();
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int hits = 0;
  constexpr int kRays = 2000;
  for (int i = 0; i < kRays; ++i) {
    // From a random point on a 400 mm sphere around the face towards a random point in its box.
    Eigen::Vector3d from(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
    from = box.center() + 400.0 * from.normalized();
    const Eigen::Vector3d to =
        box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    geometry::Ray ray;
    ray.origin = from;
    ray.direction = (to - from).normalized();
    const double max_distance = i % 4 == 0 ? 400.0 : kInfinity;
    const auto fast = face_->Intersect(ray, max_distance);
    const auto slow = face_->IntersectBruteForce(ray, max_distance);
    ASSERT_EQ(fast.has_value(), slow.has_value()) << "ray " << i;
    if (!fast) continue;
    ++hits;
    EXPECT_NEAR(fast->distance, slow->distance, kDistanceTolerance) << "ray " << i;
    EXPECT_NEAR((fast->normal - slow->normal).norm(), 0.0, kNormalTolerance) << "ray " << i;
  }
  EXPECT_GT(hits, kRays / 4);
}

TEST_F(FaceMeshBvh, FaceIsPlacedAsDocumented) {
  const IndexedMesh& mesh = face_->mesh();
  const Eigen::AlignedBox3d box = mesh.Bounds();
  Eigen::Vector3d nose = mesh.vertices.front();
  for (const auto& v : mesh.vertices)
    if (v.z() > nose.z()) nose = v;
  EXPECT_NEAR(nose.x(), 0.0, 1e-9);
  EXPECT_NEAR(box.min().z(), 0.0, 1e-9);
  EXPECT_NEAR(box.min().y() + box.max().y(), 0.0, 1e-9);
  // About 155 mm wide, 177 mm tall and 100 mm deep (subdivision shrinks it a little).
  EXPECT_NEAR(box.sizes().x(), 150.0, 10.0);
  EXPECT_NEAR(box.sizes().y(), 172.0, 10.0);
  EXPECT_NEAR(box.sizes().z(), 95.0, 10.0);
  EXPECT_EQ(mesh.triangles.size(), 898u * 16u);
}

TEST(ThesisFace, MissingOrCorruptObjThrowsMeshLoadErrorNamingTheFile) {
  ThesisSceneOptions options;
  options.face.obj_path = kDataDir / "nowhere" / "face.obj";
  std::string message =
      LoadErrorOf([&] { ThesisScene(pattern::Side::kLeft, SurfaceKind::kFace, options); });
  EXPECT_TRUE(Contains(message, options.face.obj_path.string())) << message;

  options.face.obj_path = WriteTemp("corrupt_face.obj", "v 1 2 3\nf 1 2 3\n");
  message = LoadErrorOf([&] { ThesisScene(pattern::Side::kLeft, SurfaceKind::kFace, options); });
  EXPECT_TRUE(Contains(message, options.face.obj_path.string())) << message;
  EXPECT_TRUE(Contains(message, "line 2")) << message;
}

}  // namespace
}  // namespace bsls::simulator
