#include "bsls/store/faulty_sqlite_vfs.h"

#include <sqlite3.h>

#include <atomic>
#include <cassert>
#include <cstddef>

namespace bsls::store {

struct FaultySqliteVfs::Impl {
  sqlite3_vfs vfs{};            // ours; pAppData points back to this Impl
  sqlite3_vfs* root = nullptr;  // SQLite's default VFS, doing the real work
  FaultyFileSystem* faults = nullptr;
  std::string name;
};

namespace {

// One open file of the shim: SQLite allocates szOsFile bytes for it; the
// real VFS's file object follows ours in the same allocation.
struct ShimFile {
  sqlite3_file base;
  FaultySqliteVfs::Impl* impl;
  sqlite3_file* real;
};

constexpr std::size_t kRealOffset = (sizeof(ShimFile) + 15) / 16 * 16;

FaultySqliteVfs::Impl* ImplOf(sqlite3_vfs* vfs) {
  return static_cast<FaultySqliteVfs::Impl*>(vfs->pAppData);
}
sqlite3_file* Real(sqlite3_file* file) { return reinterpret_cast<ShimFile*>(file)->real; }
FaultyFileSystem* FaultsOf(sqlite3_file* file) {
  return reinterpret_cast<ShimFile*>(file)->impl->faults;
}

int ShimClose(sqlite3_file* file) {
  sqlite3_file* real = Real(file);
  const int rc = real->pMethods ? real->pMethods->xClose(real) : SQLITE_OK;
  file->pMethods = nullptr;
  return rc;
}
int ShimRead(sqlite3_file* file, void* data, int amount, sqlite3_int64 offset) {
  return Real(file)->pMethods->xRead(Real(file), data, amount, offset);
}
int ShimWrite(sqlite3_file* file, const void* data, int amount, sqlite3_int64 offset) {
  if (auto fault = FaultsOf(file)->Check(FsOp::kDbWrite)) {
    return *fault == Fault::kEnospc ? SQLITE_FULL : SQLITE_IOERR_WRITE;
  }
  return Real(file)->pMethods->xWrite(Real(file), data, amount, offset);
}
int ShimTruncate(sqlite3_file* file, sqlite3_int64 size) {
  if (auto fault = FaultsOf(file)->Check(FsOp::kDbWrite)) {
    return *fault == Fault::kEnospc ? SQLITE_FULL : SQLITE_IOERR_TRUNCATE;
  }
  return Real(file)->pMethods->xTruncate(Real(file), size);
}
int ShimSync(sqlite3_file* file, int flags) {
  if (FaultsOf(file)->Check(FsOp::kDbSync)) return SQLITE_IOERR_FSYNC;
  return Real(file)->pMethods->xSync(Real(file), flags);
}
int ShimFileSize(sqlite3_file* file, sqlite3_int64* size) {
  return Real(file)->pMethods->xFileSize(Real(file), size);
}
int ShimLock(sqlite3_file* file, int level) {
  return Real(file)->pMethods->xLock(Real(file), level);
}
int ShimUnlock(sqlite3_file* file, int level) {
  return Real(file)->pMethods->xUnlock(Real(file), level);
}
int ShimCheckReservedLock(sqlite3_file* file, int* out) {
  return Real(file)->pMethods->xCheckReservedLock(Real(file), out);
}
int ShimFileControl(sqlite3_file* file, int op, void* arg) {
  return Real(file)->pMethods->xFileControl(Real(file), op, arg);
}
int ShimSectorSize(sqlite3_file* file) { return Real(file)->pMethods->xSectorSize(Real(file)); }
int ShimDeviceCharacteristics(sqlite3_file* file) {
  return Real(file)->pMethods->xDeviceCharacteristics(Real(file));
}
int ShimShmMap(sqlite3_file* file, int region, int size, int extend, void volatile** out) {
  return Real(file)->pMethods->xShmMap(Real(file), region, size, extend, out);
}
int ShimShmLock(sqlite3_file* file, int offset, int n, int flags) {
  return Real(file)->pMethods->xShmLock(Real(file), offset, n, flags);
}
void ShimShmBarrier(sqlite3_file* file) { Real(file)->pMethods->xShmBarrier(Real(file)); }
int ShimShmUnmap(sqlite3_file* file, int delete_flag) {
  return Real(file)->pMethods->xShmUnmap(Real(file), delete_flag);
}
int ShimFetch(sqlite3_file* file, sqlite3_int64 offset, int amount, void** out) {
  // No memory-mapped reads: every page comes through xRead (mmap_size is 0).
  (void)file;
  (void)offset;
  (void)amount;
  *out = nullptr;
  return SQLITE_OK;
}
int ShimUnfetch(sqlite3_file* file, sqlite3_int64 offset, void* page) {
  (void)file;
  (void)offset;
  (void)page;
  return SQLITE_OK;
}

const sqlite3_io_methods kShimMethods = {
    3,
    ShimClose,
    ShimRead,
    ShimWrite,
    ShimTruncate,
    ShimSync,
    ShimFileSize,
    ShimLock,
    ShimUnlock,
    ShimCheckReservedLock,
    ShimFileControl,
    ShimSectorSize,
    ShimDeviceCharacteristics,
    ShimShmMap,
    ShimShmLock,
    ShimShmBarrier,
    ShimShmUnmap,
    ShimFetch,
    ShimUnfetch,
};

int ShimOpen(sqlite3_vfs* vfs, const char* name, sqlite3_file* file, int flags, int* out_flags) {
  FaultySqliteVfs::Impl* impl = ImplOf(vfs);
  auto* shim = reinterpret_cast<ShimFile*>(file);
  shim->base.pMethods = nullptr;
  shim->impl = impl;
  shim->real = reinterpret_cast<sqlite3_file*>(reinterpret_cast<char*>(file) + kRealOffset);
  const int rc = impl->root->xOpen(impl->root, name, shim->real, flags, out_flags);
  if (shim->real->pMethods != nullptr) shim->base.pMethods = &kShimMethods;
  return rc;
}
int ShimDelete(sqlite3_vfs* vfs, const char* name, int sync_dir) {
  return ImplOf(vfs)->root->xDelete(ImplOf(vfs)->root, name, sync_dir);
}
int ShimAccess(sqlite3_vfs* vfs, const char* name, int flags, int* out) {
  return ImplOf(vfs)->root->xAccess(ImplOf(vfs)->root, name, flags, out);
}
int ShimFullPathname(sqlite3_vfs* vfs, const char* name, int size, char* out) {
  return ImplOf(vfs)->root->xFullPathname(ImplOf(vfs)->root, name, size, out);
}
void* ShimDlOpen(sqlite3_vfs* vfs, const char* name) {
  return ImplOf(vfs)->root->xDlOpen(ImplOf(vfs)->root, name);
}
void ShimDlError(sqlite3_vfs* vfs, int size, char* out) {
  ImplOf(vfs)->root->xDlError(ImplOf(vfs)->root, size, out);
}
void (*ShimDlSym(sqlite3_vfs* vfs, void* handle, const char* symbol))(void) {
  return ImplOf(vfs)->root->xDlSym(ImplOf(vfs)->root, handle, symbol);
}
void ShimDlClose(sqlite3_vfs* vfs, void* handle) {
  ImplOf(vfs)->root->xDlClose(ImplOf(vfs)->root, handle);
}
int ShimRandomness(sqlite3_vfs* vfs, int size, char* out) {
  return ImplOf(vfs)->root->xRandomness(ImplOf(vfs)->root, size, out);
}
int ShimSleep(sqlite3_vfs* vfs, int microseconds) {
  return ImplOf(vfs)->root->xSleep(ImplOf(vfs)->root, microseconds);
}
int ShimCurrentTime(sqlite3_vfs* vfs, double* out) {
  return ImplOf(vfs)->root->xCurrentTime(ImplOf(vfs)->root, out);
}
int ShimGetLastError(sqlite3_vfs* vfs, int size, char* out) {
  return ImplOf(vfs)->root->xGetLastError(ImplOf(vfs)->root, size, out);
}
int ShimCurrentTimeInt64(sqlite3_vfs* vfs, sqlite3_int64* out) {
  return ImplOf(vfs)->root->xCurrentTimeInt64(ImplOf(vfs)->root, out);
}

std::atomic<int> next_vfs_number{0};

}  // namespace

FaultySqliteVfs::FaultySqliteVfs(FaultyFileSystem& faults) : impl_(std::make_unique<Impl>()) {
  sqlite3_initialize();
  impl_->root = sqlite3_vfs_find(nullptr);
  assert(impl_->root != nullptr && impl_->root->iVersion >= 2);
  impl_->faults = &faults;
  impl_->name = "bsls-faulty-" + std::to_string(next_vfs_number++);
  sqlite3_vfs& vfs = impl_->vfs;
  vfs.iVersion = 2;
  vfs.szOsFile = static_cast<int>(kRealOffset) + impl_->root->szOsFile;
  vfs.mxPathname = impl_->root->mxPathname;
  vfs.zName = impl_->name.c_str();
  vfs.pAppData = impl_.get();
  vfs.xOpen = ShimOpen;
  vfs.xDelete = ShimDelete;
  vfs.xAccess = ShimAccess;
  vfs.xFullPathname = ShimFullPathname;
  vfs.xDlOpen = ShimDlOpen;
  vfs.xDlError = ShimDlError;
  vfs.xDlSym = ShimDlSym;
  vfs.xDlClose = ShimDlClose;
  vfs.xRandomness = ShimRandomness;
  vfs.xSleep = ShimSleep;
  vfs.xCurrentTime = ShimCurrentTime;
  vfs.xGetLastError = ShimGetLastError;
  vfs.xCurrentTimeInt64 = ShimCurrentTimeInt64;
  const int rc = sqlite3_vfs_register(&vfs, /*makeDflt=*/0);
  assert(rc == SQLITE_OK);
  (void)rc;
}

FaultySqliteVfs::~FaultySqliteVfs() { sqlite3_vfs_unregister(&impl_->vfs); }

const std::string& FaultySqliteVfs::name() const { return impl_->name; }

}  // namespace bsls::store
