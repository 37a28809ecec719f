#include "bsls/geometry/surface_mesh.h"

#include <gtest/gtest.h>

namespace bsls::geometry {
namespace {

SurfaceMesh Triangle() {
  SurfaceMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.faces = {{0, 1, 2}};
  return mesh;
}

TEST(SurfaceMesh, ATriangleWithoutAttributesIsValid) {
  std::string error;
  EXPECT_TRUE(Triangle().IsValid(&error)) << error;
}

TEST(SurfaceMesh, AttributeOfTheWrongSizeIsNamed) {
  SurfaceMesh mesh = Triangle();
  mesh.uncertainty_mm = {0.1f, 0.1f};
  std::string error;
  EXPECT_FALSE(mesh.IsValid(&error));
  EXPECT_NE(error.find("uncertainty_mm has 2 entries for 3 vertices"), std::string::npos) << error;
}

TEST(SurfaceMesh, FaceOutOfRangeOrDegenerateIsRejected) {
  SurfaceMesh mesh = Triangle();
  mesh.faces = {{0, 1, 3}};
  std::string error;
  EXPECT_FALSE(mesh.IsValid(&error));
  EXPECT_NE(error.find("face 0 refers to vertex 3"), std::string::npos) << error;
  mesh.faces = {{0, 1, 1}};
  EXPECT_FALSE(mesh.IsValid(&error));
  EXPECT_NE(error.find("repeats a vertex"), std::string::npos) << error;
}

}  // namespace
}  // namespace bsls::geometry
