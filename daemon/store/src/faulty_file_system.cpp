#include "bsls/store/faulty_file_system.h"

#include <fcntl.h>

#include <cerrno>
#include <cstring>

namespace bsls::store {

std::string_view ToString(FsOp op) {
  switch (op) {
    case FsOp::kOpen:
      return "open";
    case FsOp::kWrite:
      return "write";
    case FsOp::kRead:
      return "read";
    case FsOp::kFsync:
      return "fsync";
    case FsOp::kClose:
      return "close";
    case FsOp::kRename:
      return "rename";
    case FsOp::kUnlink:
      return "unlink";
    case FsOp::kMakeDirectory:
      return "mkdir";
    case FsOp::kFsyncDirectory:
      return "fsync-dir";
    case FsOp::kStatvfs:
      return "statvfs";
    case FsOp::kListDirectory:
      return "list-dir";
    case FsOp::kDbWrite:
      return "db-write";
    case FsOp::kDbSync:
      return "db-sync";
  }
  return "unknown";
}

namespace {

int ErrnoOf(Fault fault) { return fault == Fault::kEnospc ? ENOSPC : EIO; }

Status Injected(Fault fault, FsOp op, const std::string& what) {
  return ErrnoStatus(ErrnoOf(fault), std::string(ToString(op)), what + " (injected fault)");
}

}  // namespace

FaultyFileSystem::FaultyFileSystem(FileSystem& inner) : inner_(inner) {}

void FaultyFileSystem::FailNth(FsOp op, int nth, Fault fault) {
  std::lock_guard lock(mutex_);
  armed_[static_cast<int>(op)] = Arming{nth, false, fault};
}

void FaultyFileSystem::FailAll(FsOp op, Fault fault) {
  std::lock_guard lock(mutex_);
  armed_[static_cast<int>(op)] = Arming{0, true, fault};
}

void FaultyFileSystem::Disarm() {
  std::lock_guard lock(mutex_);
  armed_ = {};
  available_bytes_.reset();
}

void FaultyFileSystem::SetAvailableBytes(std::optional<std::uint64_t> bytes) {
  std::lock_guard lock(mutex_);
  available_bytes_ = bytes;
}

int FaultyFileSystem::count(FsOp op) const {
  std::lock_guard lock(mutex_);
  return counts_[static_cast<int>(op)];
}

void FaultyFileSystem::ResetCounts() {
  std::lock_guard lock(mutex_);
  counts_ = {};
}

int FaultyFileSystem::faults_fired() const {
  std::lock_guard lock(mutex_);
  return faults_fired_;
}

std::optional<Fault> FaultyFileSystem::Check(FsOp op) {
  std::lock_guard lock(mutex_);
  const int index = static_cast<int>(op);
  ++counts_[index];
  Arming& arming = armed_[index];
  if (arming.always) {
    ++faults_fired_;
    return arming.fault;
  }
  if (arming.remaining > 0 && --arming.remaining == 0) {
    ++faults_fired_;
    return arming.fault;
  }
  return std::nullopt;
}

Result<int> FaultyFileSystem::Open(const std::string& path, int flags, mode_t mode) {
  if (auto fault = Check(FsOp::kOpen)) return Injected(*fault, FsOp::kOpen, path);
  return inner_.Open(path, flags, mode);
}

Result<std::size_t> FaultyFileSystem::Write(int fd, const void* data, std::size_t size) {
  if (auto fault = Check(FsOp::kWrite)) {
    if (*fault == Fault::kShortWrite && size > 1) {
      return inner_.Write(fd, data, size / 2);
    }
    if (*fault != Fault::kShortWrite) {
      return Injected(*fault, FsOp::kWrite, "fd " + std::to_string(fd));
    }
  }
  return inner_.Write(fd, data, size);
}

Result<std::size_t> FaultyFileSystem::Read(int fd, void* data, std::size_t size) {
  if (auto fault = Check(FsOp::kRead)) {
    return Injected(*fault, FsOp::kRead, "fd " + std::to_string(fd));
  }
  return inner_.Read(fd, data, size);
}

Status FaultyFileSystem::Fsync(int fd) {
  if (auto fault = Check(FsOp::kFsync)) {
    return Injected(*fault, FsOp::kFsync, "fd " + std::to_string(fd));
  }
  return inner_.Fsync(fd);
}

Status FaultyFileSystem::Close(int fd) {
  if (auto fault = Check(FsOp::kClose)) {
    inner_.Close(fd);  // close(2) releases the descriptor even when it fails
    return Injected(*fault, FsOp::kClose, "fd " + std::to_string(fd));
  }
  return inner_.Close(fd);
}

Status FaultyFileSystem::Rename(const std::string& from, const std::string& to) {
  if (auto fault = Check(FsOp::kRename)) return Injected(*fault, FsOp::kRename, from);
  return inner_.Rename(from, to);
}

Status FaultyFileSystem::Unlink(const std::string& path) {
  if (auto fault = Check(FsOp::kUnlink)) return Injected(*fault, FsOp::kUnlink, path);
  return inner_.Unlink(path);
}

Status FaultyFileSystem::MakeDirectory(const std::string& path, mode_t mode) {
  if (auto fault = Check(FsOp::kMakeDirectory)) {
    return Injected(*fault, FsOp::kMakeDirectory, path);
  }
  return inner_.MakeDirectory(path, mode);
}

Status FaultyFileSystem::FsyncDirectory(const std::string& path) {
  if (auto fault = Check(FsOp::kFsyncDirectory)) {
    return Injected(*fault, FsOp::kFsyncDirectory, path);
  }
  return inner_.FsyncDirectory(path);
}

Result<SpaceInfo> FaultyFileSystem::Statvfs(const std::string& path) {
  if (auto fault = Check(FsOp::kStatvfs)) return Injected(*fault, FsOp::kStatvfs, path);
  auto space = inner_.Statvfs(path);
  std::lock_guard lock(mutex_);
  if (space.ok() && available_bytes_) space->available_bytes = *available_bytes_;
  return space;
}

Result<std::vector<std::string>> FaultyFileSystem::ListDirectory(const std::string& path) {
  if (auto fault = Check(FsOp::kListDirectory)) {
    return Injected(*fault, FsOp::kListDirectory, path);
  }
  return inner_.ListDirectory(path);
}

}  // namespace bsls::store
