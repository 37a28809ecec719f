// Surface files (contracts section 5): PLY/OBJ/STL writing, PLY reading.
#include "bsls/io/surface_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "bsls/common/errors.h"

namespace bsls::io {
namespace {

namespace fs = std::filesystem;

constexpr double kFloatMm = 1e-4;  // float32 storage of coordinates up to ~200 mm

// A fresh folder under the test's temporary directory.
fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("bsls_surface_file_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteAll(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// A seeded random mesh with every attribute.
geometry::SurfaceMesh RandomMesh(int vertices, int faces, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-150.0, 150.0);
  std::uniform_int_distribution<int> index(0, vertices - 1);
  geometry::SurfaceMesh mesh;
  for (int v = 0; v < vertices; ++v) {
    mesh.positions.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
    mesh.normals.push_back(Eigen::Vector3d(coordinate(rng), coordinate(rng), 200.0).normalized());
    mesh.uncertainty_mm.push_back(static_cast<float>(std::abs(coordinate(rng)) / 100.0));
    mesh.line.push_back(index(rng) - vertices / 2);
    mesh.flags.push_back(static_cast<std::uint8_t>(index(rng) % 8));
  }
  while (static_cast<int>(mesh.faces.size()) < faces) {
    const Eigen::Vector3i f(index(rng), index(rng), index(rng));
    if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2]) mesh.faces.push_back(f);
  }
  return mesh;
}

void ExpectSame(const geometry::SurfaceMesh& a, const geometry::SurfaceMesh& b) {
  ASSERT_EQ(a.VertexCount(), b.VertexCount());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  ASSERT_EQ(a.uncertainty_mm.size(), b.uncertainty_mm.size());
  ASSERT_EQ(a.line, b.line);
  ASSERT_EQ(a.flags, b.flags);
  ASSERT_EQ(a.faces, b.faces);
  for (std::size_t v = 0; v < a.VertexCount(); ++v) {
    EXPECT_LT((a.positions[v] - b.positions[v]).norm(), kFloatMm);
    if (!a.normals.empty()) {
      EXPECT_LT((a.normals[v] - b.normals[v]).norm(), 1e-6);
    }
    if (!a.uncertainty_mm.empty()) {
      EXPECT_FLOAT_EQ(a.uncertainty_mm[v], b.uncertainty_mm[v]);
    }
  }
}

class PlyRoundTrip : public ::testing::TestWithParam<PlyEncoding> {};

TEST_P(PlyRoundTrip, KeepsEveryAttribute) {
  const fs::path dir = TempDir("roundtrip");
  for (unsigned seed : {1u, 2u, 3u}) {
    const geometry::SurfaceMesh mesh = RandomMesh(200, 300, seed);
    const fs::path path = dir / "mesh.ply";
    WritePly(path.string(), mesh, GetParam());
    ExpectSame(mesh, ReadPly(path.string()));
  }
  fs::remove_all(dir);
}

// A point cloud: no face element at all; only positions.
TEST_P(PlyRoundTrip, PointCloudWithoutAttributes) {
  geometry::SurfaceMesh cloud;
  cloud.positions = {{1.0, 2.0, 3.0}, {-4.5, 0.25, 7.0}};
  const std::string bytes = EncodePly(cloud, GetParam());
  EXPECT_EQ(bytes.find("element face"), std::string::npos);
  EXPECT_EQ(bytes.find("uncertainty_mm"), std::string::npos);
  ExpectSame(cloud, DecodePly(bytes, "cloud.ply"));
}

INSTANTIATE_TEST_SUITE_P(Encodings, PlyRoundTrip,
                         ::testing::Values(PlyEncoding::kBinaryLittleEndian, PlyEncoding::kAscii),
                         [](const auto& test_info) {
                           return test_info.param == PlyEncoding::kAscii ? "ascii" : "binary";
                         });

TEST(PlyHeader, BinaryLittleEndianByDefaultWithOurProperties) {
  const std::string bytes = EncodePly(RandomMesh(3, 1, 4), PlyEncoding::kBinaryLittleEndian);
  for (const char* expected :
       {"format binary_little_endian 1.0", "element vertex 3", "property float nx",
        "property float uncertainty_mm", "property int line", "property uchar flags",
        "element face 1", "property list uchar int vertex_indices"})
    EXPECT_NE(bytes.find(expected), std::string::npos) << expected;
}

// Another tool's file: doubles, big-endian, extra properties and elements,
// a quad face; only x, y, z and the faces are ours.
TEST(ReadPly, SkipsUnknownPropertiesAndSplitsPolygons) {
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\ncomment from elsewhere\n"
      "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
      "property uchar red\nproperty list uchar float extra\n"
      "element face 1\nproperty uchar material\nproperty list uchar uint vertex_index\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  const auto put_be = [&bytes](const void* data, std::size_t size) {
    const char* c = static_cast<const char*>(data);
    for (std::size_t k = 0; k < size; ++k) bytes.push_back(c[size - 1 - k]);
  };
  for (int v = 0; v < 4; ++v) {
    const double xyz[3] = {double(v), 2.0 * v, -1.5};
    for (double c : xyz) put_be(&c, 8);
    bytes.push_back(char(200));  // red
    bytes.push_back(char(1));    // one extra float
    const float extra = 9.0f;
    put_be(&extra, 4);
  }
  bytes.push_back(char(7));  // material
  bytes.push_back(char(4));  // a quad
  for (std::uint32_t i : {0u, 1u, 2u, 3u}) put_be(&i, 4);
  for (std::int32_t i : {0, 1}) put_be(&i, 4);  // the edge
  const geometry::SurfaceMesh mesh = DecodePly(bytes, "other.ply");
  ASSERT_EQ(mesh.VertexCount(), 4u);
  EXPECT_TRUE(mesh.normals.empty());
  EXPECT_TRUE(mesh.line.empty());
  EXPECT_EQ(mesh.positions[3], Eigen::Vector3d(3.0, 6.0, -1.5));
  ASSERT_EQ(mesh.faces.size(), 2u);
  EXPECT_EQ(mesh.faces[1], Eigen::Vector3i(0, 2, 3));
}

// Every cut of a valid binary file, and corrupted headers, fail with an
// InputError naming the file; none crashes or allocates absurdly.
TEST(ReadPly, TruncatedAndCorruptFilesFailClearly) {
  const std::string good = EncodePly(RandomMesh(20, 10, 5), PlyEncoding::kBinaryLittleEndian);
  const std::string header_end = "end_header\n";
  const std::size_t body = good.find(header_end) + header_end.size();
  for (std::size_t cut = 0; cut < good.size(); cut += (cut < body ? 7 : 13)) {
    try {
      DecodePly(good.substr(0, cut), "cut.ply");
      ADD_FAILURE() << "accepted a file cut at " << cut << " of " << good.size();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cut.ply"), std::string::npos) << e.what();
    }
  }
  try {
    DecodePly(good.substr(0, body + 30), "short.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  const auto expect_error = [](const std::string& bytes, const std::string& reason) {
    try {
      DecodePly(bytes, "bad.ply");
      ADD_FAILURE() << "accepted: " << reason;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  expect_error("solid stl\n", "does not start with 'ply'");
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
               "no x, y, z");
  expect_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 oops\n",
      "not a number");
  expect_error(
      "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n1 2 3\n",
      "truncated");
  expect_error(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
      "face 0 refers to vertex 7");
  expect_error("ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown format");
  // 8 MiB of blank header lines: refused at 1 MiB (parsing them all took
  // seconds, minutes under the sanitizers).
  std::string padded = good;
  padded.insert(4, std::string(8 << 20, '\n'));
  expect_error(padded, "header runs past 1024 KiB");
  // An element without properties takes no bytes whatever its count: it is
  // passed over at once (this count was 1.8e19 turns of a loop), and a
  // vertex element without properties is refused.
  std::string junk = good;
  junk.insert(junk.find("element vertex"), "element junk 18446744073709551615\n");
  EXPECT_EQ(DecodePly(junk, "junk.ply").positions.size(), 20u);
  expect_error("ply\nformat ascii 1.0\nelement vertex 18446744073709551615\nend_header\n",
               "element vertex has no properties");
  // Words are split on any white space; a header with tabs and padding reads.
  std::string spaced = good;
  spaced.replace(spaced.find("format "), 7, "format\t  ");
  EXPECT_EQ(DecodePly(spaced, "spaced.ply").positions.size(), 20u);
}

TEST(ReadPly, MissingFileNamesIt) {
  try {
    ReadPly("/nonexistent/surface.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/surface.ply"), std::string::npos);
  }
}

TEST(WriteObj, VerticesNormalsAndOneBasedFaces) {
  const fs::path dir = TempDir("obj");
  geometry::SurfaceMesh mesh = RandomMesh(4, 2, 6);
  WriteObj((dir / "m.obj").string(), mesh);
  const std::string text = ReadAll(dir / "m.obj");
  std::istringstream in(text);
  int v = 0, vn = 0, f = 0;
  for (std::string line; std::getline(in, line);) {
    v += line.rfind("v ", 0) == 0;
    vn += line.rfind("vn ", 0) == 0;
    if (line.rfind("f ", 0) == 0) {
      ++f;
      const std::string first = std::to_string(mesh.faces[f - 1][0] + 1);
      EXPECT_EQ(line.substr(0, 2 + 2 * first.size() + 2), "f " + first + "//" + first);
    }
  }
  EXPECT_EQ(v, 4);
  EXPECT_EQ(vn, 4);
  EXPECT_EQ(f, 2);
  fs::remove_all(dir);
}

TEST(WriteStl, BinaryLayoutAndFacetNormals) {
  const fs::path dir = TempDir("stl");
  geometry::SurfaceMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.faces = {{0, 1, 2}};
  WriteStl((dir / "m.stl").string(), mesh);
  const std::string bytes = ReadAll(dir / "m.stl");
  ASSERT_EQ(bytes.size(), 80u + 4u + 50u);
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  EXPECT_EQ(count, 1u);
  float normal[3], third[3];
  std::memcpy(normal, bytes.data() + 84, 12);
  std::memcpy(third, bytes.data() + 84 + 12 + 24, 12);
  EXPECT_FLOAT_EQ(normal[2], 1.0f);
  EXPECT_FLOAT_EQ(third[1], 1.0f);
  geometry::SurfaceMesh cloud;
  cloud.positions = mesh.positions;
  EXPECT_THROW(WriteStl((dir / "cloud.stl").string(), cloud), std::invalid_argument);
  fs::remove_all(dir);
}

// A failed write throws OutputError and leaves the old file untouched.
TEST(WritePly, FailureLeavesNoHalfWrittenFile) {
  const fs::path dir = TempDir("atomic");
  const fs::path path = dir / "keep.ply";
  WriteAll(path, "old");
  EXPECT_THROW(WritePly((dir / "missing" / "x.ply").string(), RandomMesh(3, 1, 7)), OutputError);
  geometry::SurfaceMesh invalid = RandomMesh(3, 1, 7);
  invalid.faces.push_back({0, 1, 9});
  EXPECT_THROW(WritePly(path.string(), invalid), std::invalid_argument);
  EXPECT_EQ(ReadAll(path), "old");
  WritePly(path.string(), RandomMesh(3, 1, 7));
  EXPECT_EQ(ReadPly(path.string()).VertexCount(), 3u);
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename(), "keep.ply") << "a temporary file was left behind";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bsls::io
