// The mesh loaders (Wavefront OBJ, JSON positions/cells): files from outside,
// apart from the ray tracing in mesh.cpp so that only they carry the fuzzers'
// coverage instrumentation.
#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "bsls/simulator/mesh.h"

namespace bsls::simulator {
namespace {

std::string_view Trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

std::vector<std::string_view> SplitWhitespace(std::string_view text) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    size_t j = i;
    while (j < text.size() && text[j] != ' ' && text[j] != '\t') ++j;
    if (j > i) out.push_back(text.substr(i, j - i));
    i = j;
  }
  return out;
}

bool ParseDouble(std::string_view text, double* value) {
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size() &&
         std::isfinite(*value);
}

bool ParseInt(std::string_view text, long* value) {
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size();
}

}  // namespace

MeshLoadError::MeshLoadError(const std::filesystem::path& path, const std::string& reason)
    : std::runtime_error(path.string() + ": " + reason), path_(path), reason_(reason) {}

namespace {

// `path` open for reading; MeshLoadError saying whether it is missing or unreadable.
std::ifstream OpenMeshFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) {
    std::error_code ec;
    const bool exists = std::filesystem::exists(path, ec);
    throw MeshLoadError(path, exists ? "cannot be opened for reading" : "no such file");
  }
  return in;
}

}  // namespace

IndexedMesh LoadObj(const std::filesystem::path& path) {
  std::ifstream in = OpenMeshFile(path);
  IndexedMesh mesh;
  std::string line;
  int line_number = 0;
  auto fail = [&](const std::string& why) {
    return MeshLoadError(path, "line " + std::to_string(line_number) + ": " + why);
  };
  std::vector<int> polygon;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string_view text = Trim(line);
    if (text.empty() || text.front() == '#') continue;
    const auto fields = SplitWhitespace(text);
    if (fields[0] == "v") {
      if (fields.size() < 4 || fields.size() > 5)
        throw fail("vertex needs 3 coordinates (optionally a 4th weight)");
      Eigen::Vector3d v;
      for (int k = 0; k < 3; ++k)
        if (!ParseDouble(fields[k + 1], &v[k]))
          throw fail("vertex coordinate '" + std::string(fields[k + 1]) +
                     "' is not a finite number");
      mesh.vertices.push_back(v);
    } else if (fields[0] == "f") {
      if (fields.size() < 4) throw fail("face needs at least 3 vertices");
      polygon.clear();
      for (size_t k = 1; k < fields.size(); ++k) {
        const std::string_view ref = fields[k].substr(0, fields[k].find('/'));
        long index = 0;
        if (!ParseInt(ref, &index) || index == 0)
          throw fail("face vertex reference '" + std::string(fields[k]) + "' is not an index");
        const long n = static_cast<long>(mesh.vertices.size());
        const long resolved = index > 0 ? index - 1 : n + index;
        if (resolved < 0 || resolved >= n)
          throw fail("face refers to vertex " + std::to_string(index) + " of " + std::to_string(n) +
                     " defined so far");
        polygon.push_back(static_cast<int>(resolved));
      }
      for (size_t k = 1; k + 1 < polygon.size(); ++k) {
        const std::array<int, 3> tri{polygon[0], polygon[k], polygon[k + 1]};
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
          throw fail("face repeats a vertex");
        mesh.triangles.push_back(tri);
      }
    }
    // Other statements (vt, vn, g, s, usemtl, mtllib, o, ...) carry nothing we use.
  }
  if (in.bad()) throw MeshLoadError(path, "read error after line " + std::to_string(line_number));
  if (mesh.vertices.empty()) throw MeshLoadError(path, "no vertices ('v' lines) in the file");
  if (mesh.triangles.empty()) throw MeshLoadError(path, "no faces ('f' lines) in the file");
  return mesh;
}

IndexedMesh LoadMeshJson(const std::filesystem::path& path) {
  std::ifstream in = OpenMeshFile(path);
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw MeshLoadError(path, std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object() || !doc.contains("positions") || !doc.contains("cells"))
    throw MeshLoadError(path, "expected an object with \"positions\" and \"cells\"");
  const auto& positions = doc["positions"];
  const auto& cells = doc["cells"];
  if (!positions.is_array() || !cells.is_array())
    throw MeshLoadError(path, "\"positions\" and \"cells\" must be arrays");
  IndexedMesh mesh;
  mesh.vertices.reserve(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const auto& p = positions[i];
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() ||
        !p[2].is_number())
      throw MeshLoadError(path, "positions[" + std::to_string(i) + "] is not [x, y, z]");
    const Eigen::Vector3d v(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    if (!v.allFinite())
      throw MeshLoadError(path, "positions[" + std::to_string(i) + "] is not finite");
    mesh.vertices.push_back(v);
  }
  const long n = static_cast<long>(mesh.vertices.size());
  mesh.triangles.reserve(cells.size());
  for (size_t i = 0; i < cells.size(); ++i) {
    const auto& c = cells[i];
    if (!c.is_array() || c.size() != 3)
      throw MeshLoadError(path, "cells[" + std::to_string(i) + "] is not [i, j, k]");
    std::array<int, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      if (!c[k].is_number_integer())
        throw MeshLoadError(path, "cells[" + std::to_string(i) + "] holds a non-integer index");
      const long index = c[k].get<long>();
      if (index < 0 || index >= n)
        throw MeshLoadError(path, "cells[" + std::to_string(i) + "] refers to vertex " +
                                      std::to_string(index) + " of " + std::to_string(n));
      tri[k] = static_cast<int>(index);
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      throw MeshLoadError(path, "cells[" + std::to_string(i) + "] repeats a vertex");
    mesh.triangles.push_back(tri);
  }
  if (mesh.triangles.empty()) throw MeshLoadError(path, "no triangles in \"cells\"");
  return mesh;
}

}  // namespace bsls::simulator
