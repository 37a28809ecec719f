// The only state of a processing replica: calibration files by content hash
// ("sha256:<hex>" of the file's bytes), parsed and checked once, kept most
// recently used first up to a number of entries. Two replicas given the same
// file give it the same id, so a client may name a calibration by id on any
// replica that has seen it and send the file to one that has not.
//
// Thread-safety: every member is safe from any thread; entries are immutable
// and shared, so one evicted while a call uses it stays valid for that call.
#ifndef BSLS_PROCESSING_CALIBRATION_CACHE_H_
#define BSLS_PROCESSING_CALIBRATION_CACHE_H_

#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "bsls/calibration/side_calibration.h"

namespace bsls::processing {

// A calibration file bytes larger than this are refused (a real one is a few
// tens of kilobytes).
inline constexpr std::size_t kMaxCalibrationBytes = 4u << 20;

struct CachedCalibration {
  std::string id;    // "sha256:<hex>"
  std::string yaml;  // the file's bytes
  calibration::SideCalibration calibration;
  std::string software_version;  // that wrote the file
};

class CalibrationCache {
 public:
  // max_entries >= 1 (asserted: the configuration checks it).
  explicit CalibrationCache(std::size_t max_entries);

  // The id of a calibration file's bytes.
  static std::string IdOf(std::string_view yaml);

  // Parses, checks and caches `yaml` (or finds it cached); throws
  // calibration::CalibrationFileError naming `name` and the reason for a
  // file that is not a usable calibration or larger than kMaxCalibrationBytes.
  std::shared_ptr<const CachedCalibration> Put(std::string yaml, const std::string& name);
  // The cached calibration `id`; nullptr when this replica does not hold it.
  std::shared_ptr<const CachedCalibration> Find(const std::string& id);
  // Entries held now.
  std::size_t size() const;

 private:
  const std::size_t max_entries_;
  mutable std::mutex mutex_;
  std::list<std::shared_ptr<const CachedCalibration>> entries_;  // most recent first
  std::map<std::string, std::list<std::shared_ptr<const CachedCalibration>>::iterator> by_id_;
};

}  // namespace bsls::processing

#endif  // BSLS_PROCESSING_CALIBRATION_CACHE_H_
