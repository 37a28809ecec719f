#include "bsls/io/surface_file.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "bsls/common/atomic_file.h"

namespace bsls::io {
namespace {

// ---------------------------------------------------------------- writing

void CheckMesh(const std::string& path, const geometry::SurfaceMesh& mesh) {
  std::string why;
  if (!mesh.IsValid(&why)) throw std::invalid_argument(path + ": cannot write: " + why);
  if (mesh.VertexCount() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument(path + ": cannot write: too many vertices");
}

// Appends a value's bytes in little-endian order.
template <typename T>
void PutLittle(std::string* out, T value) {
  std::array<char, sizeof(T)> bytes;
  std::memcpy(bytes.data(), &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes.begin(), bytes.end());
  out->append(bytes.data(), bytes.size());
}

// Shortest text that reads back as the same float.
std::string FloatText(float value) {
  std::array<char, 32> buffer;
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

// ---------------------------------------------------------------- reading

enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<Type> ParseType(const std::string& name) {
  if (name == "char" || name == "int8") return Type::kInt8;
  if (name == "uchar" || name == "uint8") return Type::kUint8;
  if (name == "short" || name == "int16") return Type::kInt16;
  if (name == "ushort" || name == "uint16") return Type::kUint16;
  if (name == "int" || name == "int32") return Type::kInt32;
  if (name == "uint" || name == "uint32") return Type::kUint32;
  if (name == "float" || name == "float32") return Type::kFloat32;
  if (name == "double" || name == "float64") return Type::kFloat64;
  return std::nullopt;
}

std::size_t SizeOf(Type type) {
  switch (type) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 1;
}

struct Property {
  std::string name;
  Type type = Type::kFloat32;
  bool is_list = false;
  Type count_type = Type::kUint8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kLittle, kBig };

// Reads the values of a PLY body one at a time; every failure names the file.
class BodyReader {
 public:
  BodyReader(std::string_view body, Format format, const std::string& name)
      : body_(body), format_(format), name_(name) {}

  double Read(Type type, const std::string& what) {
    return format_ == Format::kAscii ? ReadText(what) : ReadBinary(type, what);
  }
  std::size_t remaining() const { return body_.size() - pos_; }
  [[noreturn]] void Fail(const std::string& why) const {
    throw InputError(name_ + ": corrupt PLY: " + why);
  }

 private:
  double ReadBinary(Type type, const std::string& what) {
    const std::size_t size = SizeOf(type);
    if (body_.size() - pos_ < size)
      throw InputError(name_ + ": truncated PLY: the file ends in " + what);
    std::array<char, 8> bytes{};
    std::memcpy(bytes.data(), body_.data() + pos_, size);
    pos_ += size;
    const bool swap = (format_ == Format::kBig) != (std::endian::native == std::endian::big);
    if (swap) std::reverse(bytes.begin(), bytes.begin() + size);
    switch (type) {
      case Type::kInt8:
        return Get<std::int8_t>(bytes);
      case Type::kUint8:
        return Get<std::uint8_t>(bytes);
      case Type::kInt16:
        return Get<std::int16_t>(bytes);
      case Type::kUint16:
        return Get<std::uint16_t>(bytes);
      case Type::kInt32:
        return Get<std::int32_t>(bytes);
      case Type::kUint32:
        return Get<std::uint32_t>(bytes);
      case Type::kFloat32:
        return Get<float>(bytes);
      case Type::kFloat64:
        return Get<double>(bytes);
    }
    return 0.0;
  }
  template <typename T>
  static double Get(const std::array<char, 8>& bytes) {
    T value;
    std::memcpy(&value, bytes.data(), sizeof(T));
    return static_cast<double>(value);
  }
  double ReadText(const std::string& what) {
    while (pos_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    if (pos_ == body_.size()) throw InputError(name_ + ": truncated PLY: the file ends in " + what);
    std::size_t end = pos_;
    while (end < body_.size() && !std::isspace(static_cast<unsigned char>(body_[end]))) ++end;
    double value = 0.0;
    const auto result = std::from_chars(body_.data() + pos_, body_.data() + end, value);
    if (result.ec != std::errc() || result.ptr != body_.data() + end)
      Fail("'" + std::string(body_.substr(pos_, std::min<std::size_t>(end - pos_, 32))) +
           "' is not a number in " + what);
    pos_ = end;
    return value;
  }

  std::string_view body_;
  Format format_;
  const std::string& name_;
  std::size_t pos_ = 0;
};

// Longest PLY header read (bytes); comments included.
constexpr std::size_t kMaxPlyHeaderBytes = 1 << 20;

// The next header line (without the line end), advancing `pos`.
std::optional<std::string_view> NextLine(std::string_view bytes, std::size_t* pos) {
  if (*pos >= bytes.size()) return std::nullopt;
  const std::size_t end = bytes.find('\n', *pos);
  if (end == std::string_view::npos) return std::nullopt;  // the header never ends
  std::string_view line = bytes.substr(*pos, end - *pos);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  *pos = end + 1;
  return line;
}

// The whitespace-separated words of `line`.
std::vector<std::string> Words(std::string_view line) {
  constexpr std::string_view kSpace = " \t\r\f\v";
  std::vector<std::string> words;
  for (std::size_t at = line.find_first_not_of(kSpace); at != std::string_view::npos;) {
    const std::size_t end = std::min(line.find_first_of(kSpace, at), line.size());
    words.emplace_back(line.substr(at, end - at));
    at = line.find_first_not_of(kSpace, end);
  }
  return words;
}

bool IsIndexList(const std::string& name) {
  return name == "vertex_indices" || name == "vertex_index";
}

// The error for a header that cannot be read as a surface's.
InputError HeaderError(const std::string& name, const std::string& why) {
  return InputError(name + ": not a usable PLY file: " + why);
}

// One header "property" line's property; throws on a malformed one.
Property ParseProperty(const std::vector<std::string>& w, std::string_view line,
                       const std::string& name) {
  Property p;
  if (w.size() == 5 && w[1] == "list") {
    const auto count = ParseType(w[2]), item = ParseType(w[3]);
    if (!count || !item || *count == Type::kFloat32 || *count == Type::kFloat64)
      throw HeaderError(name, "bad list property '" + std::string(line) + "'");
    p = {w[4], *item, true, *count};
  } else if (w.size() == 3) {
    const auto type = ParseType(w[1]);
    if (!type) throw HeaderError(name, "unknown type '" + w[1] + "'");
    p = {w[2], *type, false, Type::kUint8};
  } else {
    throw HeaderError(name, "bad property line '" + std::string(line) + "'");
  }
  return p;
}

// A PLY header: the body's format, its elements in file order, and where
// the body starts in the file.
struct PlyHeader {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t body_start = 0;
};

// Reads the header up to and including its end_header line; throws
// InputError naming the file on anything it cannot use.
PlyHeader ReadPlyHeader(std::string_view bytes, const std::string& name) {
  std::size_t pos = 0;
  auto line = NextLine(bytes, &pos);
  if (!line || *line != "ply") throw HeaderError(name, "it does not start with 'ply'");
  std::optional<Format> format;
  PlyHeader header;
  std::vector<Element>& elements = header.elements;
  bool ended = false;
  while (!ended) {
    // A header is a few hundred bytes; one of megabytes is not a surface's.
    if (pos > kMaxPlyHeaderBytes)
      throw HeaderError(name, "the header runs past " + std::to_string(kMaxPlyHeaderBytes >> 10) +
                                  " KiB without an end_header line");
    line = NextLine(bytes, &pos);
    if (!line) throw HeaderError(name, "the header has no end_header line");
    const std::vector<std::string> w = Words(*line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      ended = true;
    } else if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") throw HeaderError(name, "bad format line");
      if (w[1] == "ascii")
        format = Format::kAscii;
      else if (w[1] == "binary_little_endian")
        format = Format::kLittle;
      else if (w[1] == "binary_big_endian")
        format = Format::kBig;
      else
        throw HeaderError(name, "unknown format '" + w[1] + "'");
    } else if (w[0] == "element") {
      if (w.size() != 3) throw HeaderError(name, "bad element line '" + std::string(*line) + "'");
      Element e;
      e.name = w[1];
      const auto r = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (r.ec != std::errc() || r.ptr != w[2].data() + w[2].size())
        throw HeaderError(name, "bad count in '" + std::string(*line) + "'");
      elements.push_back(e);
    } else if (w[0] == "property") {
      if (elements.empty()) throw HeaderError(name, "a property before any element");
      elements.back().properties.push_back(ParseProperty(w, *line, name));
    } else {
      throw HeaderError(name, "unknown header line '" + std::string(*line) + "'");
    }
  }
  if (!format) throw HeaderError(name, "no format line");
  header.format = *format;
  header.body_start = pos;
  return header;
}

// Reads one list property's items and throws them away.
void SkipList(BodyReader& body, const Property& p, const std::string& what) {
  const double n = body.Read(p.count_type, what);
  if (n < 0) body.Fail("negative list length in " + what);
  for (double i = 0; i < n; ++i) body.Read(p.type, what);
}

// Where each vertex property the mesh keeps sits in a vertex's values; -1
// for one the file does not have.
struct VertexColumns {
  int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1, sigma = -1, line = -1, flags = -1;
};

VertexColumns FindVertexColumns(const Element& e) {
  VertexColumns c;
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    const Property& p = e.properties[k];
    if (p.is_list) continue;
    const int index = static_cast<int>(k);
    if (p.name == "x")
      c.x = index;
    else if (p.name == "y")
      c.y = index;
    else if (p.name == "z")
      c.z = index;
    else if (p.name == "nx")
      c.nx = index;
    else if (p.name == "ny")
      c.ny = index;
    else if (p.name == "nz")
      c.nz = index;
    else if (p.name == "uncertainty_mm")
      c.sigma = index;
    else if (p.name == "line")
      c.line = index;
    else if (p.name == "flags")
      c.flags = index;
  }
  return c;
}

// Stores vertex v's values in the mesh; a value its type cannot hold fails
// the body.
void StoreVertex(const std::vector<double>& values, const VertexColumns& c, bool normals,
                 std::uint64_t v, const std::string& what, BodyReader& body,
                 geometry::SurfaceMesh& mesh) {
  mesh.positions[v] = {values[c.x], values[c.y], values[c.z]};
  if (!mesh.positions[v].allFinite()) body.Fail("non-finite position in " + what);
  if (normals) mesh.normals[v] = {values[c.nx], values[c.ny], values[c.nz]};
  // Values the types below cannot hold are input errors, never casts.
  if (c.sigma >= 0) {
    const double sigma = values[c.sigma];
    if (!(sigma >= 0.0 && sigma <= std::numeric_limits<float>::max()))
      body.Fail("uncertainty_mm is not a finite value >= 0 in " + what);
    mesh.uncertainty_mm[v] = static_cast<float>(sigma);
  }
  if (c.line >= 0) {
    const double p = values[c.line];
    if (!(p >= std::numeric_limits<std::int32_t>::min() &&
          p <= std::numeric_limits<std::int32_t>::max()) ||
        p != std::floor(p))
      body.Fail("line is not a 32-bit integer in " + what);
    mesh.line[v] = static_cast<std::int32_t>(p);
  }
  if (c.flags >= 0) {
    const double flags = values[c.flags];
    if (!(flags >= 0.0 && flags <= 255.0) || flags != std::floor(flags))
      body.Fail("flags is not a byte in " + what);
    mesh.flags[v] = static_cast<std::uint8_t>(flags);
  }
}

// Reads the vertex element into the mesh's per-vertex arrays; needs x, y, z.
void ReadVertices(const Element& e, BodyReader& body, const std::string& name,
                  geometry::SurfaceMesh& mesh) {
  const VertexColumns c = FindVertexColumns(e);
  if (c.x < 0 || c.y < 0 || c.z < 0)
    throw InputError(name + ": not a usable PLY file: the vertices have no x, y, z");
  const bool normals = c.nx >= 0 && c.ny >= 0 && c.nz >= 0;
  mesh.positions.resize(e.count);
  if (normals) mesh.normals.resize(e.count);
  if (c.sigma >= 0) mesh.uncertainty_mm.resize(e.count);
  if (c.line >= 0) mesh.line.resize(e.count);
  if (c.flags >= 0) mesh.flags.resize(e.count);
  std::vector<double> values(e.properties.size());
  for (std::uint64_t v = 0; v < e.count; ++v) {
    const std::string what = "vertex " + std::to_string(v) + " of " + std::to_string(e.count);
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      if (p.is_list) {  // an unknown list on a vertex: skipped
        SkipList(body, p, what);
      } else {
        values[k] = body.Read(p.type, what);
      }
    }
    StoreVertex(values, c, normals, v, what, body, mesh);
  }
}

// Reads the face element, each polygon of its index list appended to the
// mesh's triangles as a fan.
void ReadFaces(const Element& e, BodyReader& body, const std::string& name,
               geometry::SurfaceMesh& mesh) {
  int index_list = -1;
  for (std::size_t k = 0; k < e.properties.size(); ++k)
    if (e.properties[k].is_list && IsIndexList(e.properties[k].name))
      index_list = static_cast<int>(k);
  if (index_list < 0)
    throw InputError(name + ": not a usable PLY file: the faces have no vertex_indices");
  mesh.faces.reserve(e.count);
  std::vector<int> polygon;
  for (std::uint64_t f = 0; f < e.count; ++f) {
    const std::string what = "face " + std::to_string(f) + " of " + std::to_string(e.count);
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      if (!p.is_list) {
        body.Read(p.type, what);
        continue;
      }
      const double n = body.Read(p.count_type, what);
      if (n < 0 || n != std::floor(n)) body.Fail("bad list length in " + what);
      polygon.clear();
      for (double i = 0; i < n; ++i) {
        const double index = body.Read(p.type, what);
        if (static_cast<int>(k) == index_list) {
          if (index < 0 || index != std::floor(index) || index > 2147483647.0)
            body.Fail("bad vertex index in " + what);
          polygon.push_back(static_cast<int>(index));
        }
      }
      if (static_cast<int>(k) != index_list) continue;
      if (polygon.size() < 3) body.Fail(what + " has fewer than 3 vertices");
      for (std::size_t i = 1; i + 1 < polygon.size(); ++i)  // a fan
        mesh.faces.emplace_back(polygon[0], polygon[i], polygon[i + 1]);
    }
  }
}

// Reads an element we do not use and throws its values away.
void SkipElement(const Element& e, BodyReader& body) {
  for (std::uint64_t i = 0; i < e.count; ++i)
    for (const Property& p : e.properties) {
      const std::string what = e.name + " " + std::to_string(i);
      if (p.is_list) {
        SkipList(body, p, what);
      } else {
        body.Read(p.type, what);
      }
    }
}

}  // namespace

std::string EncodePly(const geometry::SurfaceMesh& mesh, PlyEncoding encoding) {
  const bool ascii = encoding == PlyEncoding::kAscii;
  const bool normals = !mesh.normals.empty(), sigma = !mesh.uncertainty_mm.empty();
  const bool line = !mesh.line.empty(), flags = !mesh.flags.empty();
  std::ostringstream header;
  header << "ply\nformat " << (ascii ? "ascii" : "binary_little_endian") << " 1.0\n"
         << "comment BSLS surface: world millimetres (x right, y up, z towards the cameras)\n"
         << "element vertex " << mesh.VertexCount() << "\n"
         << "property float x\nproperty float y\nproperty float z\n";
  if (normals) header << "property float nx\nproperty float ny\nproperty float nz\n";
  if (sigma) header << "property float uncertainty_mm\n";
  if (line) header << "property int line\n";
  if (flags) header << "property uchar flags\n";
  if (!mesh.faces.empty())
    header << "element face " << mesh.faces.size() << "\n"
           << "property list uchar int vertex_indices\n";
  header << "end_header\n";
  std::string out = header.str();
  const std::size_t vertex_bytes =
      12 + (normals ? 12 : 0) + (sigma ? 4 : 0) + (line ? 4 : 0) + (flags ? 1 : 0);
  out.reserve(out.size() + mesh.VertexCount() * (ascii ? 4 * vertex_bytes : vertex_bytes) +
              mesh.faces.size() * (ascii ? 40 : 13));
  for (std::size_t v = 0; v < mesh.VertexCount(); ++v) {
    std::array<float, 6> xyz_n{};
    int floats = 3;
    for (int k = 0; k < 3; ++k) xyz_n[k] = static_cast<float>(mesh.positions[v][k]);
    if (normals) {
      for (int k = 0; k < 3; ++k) xyz_n[3 + k] = static_cast<float>(mesh.normals[v][k]);
      floats = 6;
    }
    if (ascii) {
      std::string row;
      for (int k = 0; k < floats; ++k) row += (k ? " " : "") + FloatText(xyz_n[k]);
      if (sigma) row += " " + FloatText(mesh.uncertainty_mm[v]);
      if (line) row += " " + std::to_string(mesh.line[v]);
      if (flags) row += " " + std::to_string(static_cast<int>(mesh.flags[v]));
      out += row;
      out += '\n';
    } else {
      for (int k = 0; k < floats; ++k) PutLittle(&out, xyz_n[k]);
      if (sigma) PutLittle(&out, mesh.uncertainty_mm[v]);
      if (line) PutLittle(&out, mesh.line[v]);
      if (flags) PutLittle(&out, mesh.flags[v]);
    }
  }
  for (const Eigen::Vector3i& f : mesh.faces) {
    if (ascii) {
      out += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) +
             "\n";
    } else {
      PutLittle(&out, std::uint8_t{3});
      for (int k = 0; k < 3; ++k) PutLittle(&out, static_cast<std::int32_t>(f[k]));
    }
  }
  return out;
}

void WritePly(const std::string& path, const geometry::SurfaceMesh& mesh, PlyEncoding encoding) {
  CheckMesh(path, mesh);
  WriteFileAtomically(path, EncodePly(mesh, encoding));
}

void WriteObj(const std::string& path, const geometry::SurfaceMesh& mesh) {
  CheckMesh(path, mesh);
  std::string out = "# BSLS surface: world millimetres (x right, y up, z towards the cameras)\n";
  for (const Eigen::Vector3d& p : mesh.positions)
    out += "v " + FloatText(float(p.x())) + " " + FloatText(float(p.y())) + " " +
           FloatText(float(p.z())) + "\n";
  for (const Eigen::Vector3d& n : mesh.normals)
    out += "vn " + FloatText(float(n.x())) + " " + FloatText(float(n.y())) + " " +
           FloatText(float(n.z())) + "\n";
  const bool normals = !mesh.normals.empty();
  for (const Eigen::Vector3i& f : mesh.faces) {
    out += "f";
    for (int k = 0; k < 3; ++k) {
      const std::string index = std::to_string(f[k] + 1);
      out += " " + index + (normals ? "//" + index : "");
    }
    out += "\n";
  }
  WriteFileAtomically(path, out);
}

void WriteStl(const std::string& path, const geometry::SurfaceMesh& mesh) {
  CheckMesh(path, mesh);
  if (mesh.faces.empty())
    throw std::invalid_argument(path +
                                ": cannot write STL: the mesh has no triangles "
                                "(a point cloud; write PLY)");
  if (mesh.faces.size() > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument(path + ": cannot write STL: too many triangles");
  std::string out(80, ' ');
  const std::string title = "BSLS surface, world mm";
  std::copy(title.begin(), title.end(), out.begin());
  PutLittle(&out, static_cast<std::uint32_t>(mesh.faces.size()));
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d& a = mesh.positions[f[0]];
    const Eigen::Vector3d& b = mesh.positions[f[1]];
    const Eigen::Vector3d& c = mesh.positions[f[2]];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() > 0.0) n.normalize();
    for (int k = 0; k < 3; ++k) PutLittle(&out, static_cast<float>(n[k]));
    for (const Eigen::Vector3d* v : {&a, &b, &c})
      for (int k = 0; k < 3; ++k) PutLittle(&out, static_cast<float>((*v)[k]));
    PutLittle(&out, std::uint16_t{0});
  }
  WriteFileAtomically(path, out);
}

void WriteSurface(const std::string& path, const geometry::SurfaceMesh& mesh,
                  PlyEncoding ply_encoding) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".ply") return WritePly(path, mesh, ply_encoding);
  if (extension == ".obj") return WriteObj(path, mesh);
  if (extension == ".stl") return WriteStl(path, mesh);
  throw std::invalid_argument(path + ": unknown surface format '" + extension +
                              "' (use .ply, .obj or .stl)");
}

geometry::SurfaceMesh DecodePly(std::string_view bytes, const std::string& name) {
  const PlyHeader header = ReadPlyHeader(bytes, name);
  BodyReader body(bytes.substr(header.body_start), header.format, name);
  geometry::SurfaceMesh mesh;
  bool seen_vertex = false;
  for (const Element& e : header.elements) {
    // Every item takes at least one byte (binary) or two characters (ASCII):
    // a count the rest of the file cannot hold is refused before allocating.
    std::size_t min_item = 0;
    for (const Property& p : e.properties)
      min_item += p.is_list ? SizeOf(p.count_type) : SizeOf(p.type);
    if (header.format == Format::kAscii) min_item = 2 * e.properties.size();
    if (min_item > 0 && e.count > body.remaining() / min_item)
      throw InputError(name + ": truncated PLY: " + std::to_string(e.count) + " " + e.name +
                       " items do not fit in the rest of the file");
    // Items without properties take no bytes, whatever their count: nothing
    // to read, and no loop as long as the count.
    if (e.properties.empty()) {
      if (e.name == "vertex" || e.name == "face")
        throw HeaderError(name, "element " + e.name + " has no properties");
      continue;
    }
    if (e.name == "vertex") {
      if (seen_vertex) body.Fail("two vertex elements");
      seen_vertex = true;
      ReadVertices(e, body, name, mesh);
    } else if (e.name == "face") {
      ReadFaces(e, body, name, mesh);
    } else {  // an element we do not use: skipped
      SkipElement(e, body);
    }
  }
  if (!seen_vertex) throw InputError(name + ": not a usable PLY file: no vertex element");
  std::string why;
  if (!mesh.IsValid(&why)) throw InputError(name + ": corrupt PLY: " + why);
  return mesh;
}

geometry::SurfaceMesh ReadPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read");
  return DecodePly(buffer.str(), path);
}

}  // namespace bsls::io
