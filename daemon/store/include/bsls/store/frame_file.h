// The on-disk form of one frame: a binary PGM ("P5", maxval 255), which any
// image viewer opens and which stores 8-bit grey losslessly:
//
//   P5\n
//   # bsls-frame 1 capture=<id> camera=<left|right|third>\n
//   <width> <height>\n
//   255\n
//   <width * height bytes, row major, top row first, no padding>
//
// Stride padding is not stored (it is not image content); frames read back
// are packed, stride == width. The comment line ties the file to its capture
// for a human; the index, not the comment, is authoritative.
//
// Files are named "<capture id>-<camera>.pgm" in <root>/frames/; a file being
// written is named ".tmp-<final name>" in the same directory (so the rename
// that publishes it stays within one filesystem and is atomic).
//
// Thread-safety: free functions; concurrent calls on different files are safe.
#ifndef BSLS_STORE_FRAME_FILE_H_
#define BSLS_STORE_FRAME_FILE_H_

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/framestore/framestore.h"
#include "bsls/store/capture_id.h"
#include "bsls/store/file_system.h"

namespace bsls::store {

// "<id>-<camera>.pgm".
std::string FrameFileName(const CaptureId& id, framestore::Camera camera);

// The capture and camera a frame file name (made by FrameFileName) stands for.
struct FrameFileNameParts {
  CaptureId id;
  framestore::Camera camera;
};
// Parses a name made by FrameFileName; nullopt for any other name.
std::optional<FrameFileNameParts> ParseFrameFileName(std::string_view name);

// The complete PGM header of a frame of the given size.
std::string FrameFileHeader(const CaptureId& id, framestore::Camera camera, int width, int height);

// Bytes a frame file of that size occupies.
std::uint64_t FrameFileBytes(const CaptureId& id, framestore::Camera camera, int width, int height);

// Writes `frame` to <directory>/<name> atomically: creates the temporary file
// exclusively, writes header and pixels (continuing after short writes),
// fsyncs, closes and renames it over the final name. Does NOT fsync the
// directory: the caller does that once for all files of a capture. Returns
// the file's size. On failure the temporary file is removed (best effort)
// and the status names the step, the file and the reason.
Result<std::uint64_t> WriteFrameFile(FileSystem& fs, const std::string& directory,
                                     const std::string& name, const CaptureId& id,
                                     const framestore::GreyFrame& frame);

// A frame file's content.
struct FrameFileContent {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height
  std::uint64_t file_bytes = 0;
};

// Reads and parses a frame file. kNotFound when it is missing, kDataLoss when
// it is not a well-formed 8-bit PGM of exactly header + width*height bytes,
// I/O errors as the FileSystem reports them.
Result<FrameFileContent> ReadFrameFile(FileSystem& fs, const std::string& path);

}  // namespace bsls::store

#endif  // BSLS_STORE_FRAME_FILE_H_
