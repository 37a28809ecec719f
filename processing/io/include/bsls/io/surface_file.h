// Surface files (contracts section 5): a geometry::SurfaceMesh written as
// PLY (binary little-endian or ASCII), Wavefront OBJ or binary STL, and read
// back from PLY.
//
// Units and frame: vertices in world millimetres (contracts section 3), as
// 32-bit floats in every format; faces are triangles, counter-clockwise seen
// from the side the surface faces. A point cloud (no faces) is a PLY without
// a face element.
//
// PLY vertex properties written (only those the mesh has):
//   float x, y, z                      position, mm
//   float nx, ny, nz                   unit normal
//   float uncertainty_mm               1-sigma position uncertainty, mm
//   int   line                         p label of the stripe
//   uchar flags                        geometry::VertexFlag bits
// and "element face" with "property list uchar int vertex_indices".
// Reading accepts any PLY 1.0 (ascii, binary_little_endian,
// binary_big_endian): x, y, z are required, the others optional (normals
// only when all of nx, ny, nz are there), unknown properties and elements
// are skipped, faces with more than three vertices are split into a fan.
//
// Errors: writers throw OutputError naming the file and the reason (the
// target is written atomically: temporary file + rename, so a failed write
// leaves no half-written file), std::invalid_argument for a mesh that is not
// valid (SurfaceMesh::IsValid) or cannot be stored in the format; the reader
// throws InputError naming the file and the reason (missing, not PLY,
// unsupported, truncated, corrupt).
//
// Thread-safety: pure functions; concurrent writes to one path are not safe.
#ifndef BSLS_IO_SURFACE_FILE_H_
#define BSLS_IO_SURFACE_FILE_H_

#include <string>
#include <string_view>

#include "bsls/geometry/surface_mesh.h"
#include "bsls/io/frame_file.h"

namespace bsls::io {

enum class PlyEncoding { kBinaryLittleEndian, kAscii };

// Writes the mesh as PLY with every attribute it has (see above).
void WritePly(const std::string& path, const geometry::SurfaceMesh& mesh,
              PlyEncoding encoding = PlyEncoding::kBinaryLittleEndian);
// Writes the mesh as Wavefront OBJ: "v x y z", "vn" when it has normals,
// "f a//a b//b c//c" (1-based). Attributes other than normals are not kept.
void WriteObj(const std::string& path, const geometry::SurfaceMesh& mesh);
// Writes the triangles as binary STL (facet normals from the vertices).
// std::invalid_argument for a point cloud (STL holds triangles only).
void WriteStl(const std::string& path, const geometry::SurfaceMesh& mesh);

// Writes the mesh in the format its extension names: .ply (binary unless
// `ply_encoding` says ASCII), .obj or .stl (case-insensitive). Throws
// std::invalid_argument naming the path for any other extension.
void WriteSurface(const std::string& path, const geometry::SurfaceMesh& mesh,
                  PlyEncoding ply_encoding = PlyEncoding::kBinaryLittleEndian);

// The bytes WritePly would write (for tests and in-memory use).
std::string EncodePly(const geometry::SurfaceMesh& mesh, PlyEncoding encoding);
// Reads a PLY file. Throws InputError naming the file and the reason.
geometry::SurfaceMesh ReadPly(const std::string& path);
// Parses PLY bytes; `name` stands for the file in error messages.
geometry::SurfaceMesh DecodePly(std::string_view bytes, const std::string& name);

}  // namespace bsls::io

#endif  // BSLS_IO_SURFACE_FILE_H_
