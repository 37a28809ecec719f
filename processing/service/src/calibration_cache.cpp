#include "bsls/processing/calibration_cache.h"

#include <cassert>

#include "bsls/calibration/calibration_file.h"
#include "bsls/common/sha256.h"

namespace bsls::processing {

CalibrationCache::CalibrationCache(std::size_t max_entries) : max_entries_(max_entries) {
  assert(max_entries >= 1);
}

std::string CalibrationCache::IdOf(std::string_view yaml) { return "sha256:" + Sha256Hex(yaml); }

std::shared_ptr<const CachedCalibration> CalibrationCache::Put(std::string yaml,
                                                               const std::string& name) {
  if (yaml.size() > kMaxCalibrationBytes)
    throw calibration::CalibrationFileError(name + ": " + std::to_string(yaml.size()) +
                                            " bytes, more than a calibration file may have (" +
                                            std::to_string(kMaxCalibrationBytes) + ")");
  const std::string id = IdOf(yaml);
  if (auto found = Find(id)) return found;
  // Parsed outside the lock: a slow parse does not hold up other callers.
  calibration::CalibrationRecord record = calibration::CalibrationFromYaml(yaml, name);
  auto entry = std::make_shared<const CachedCalibration>(CachedCalibration{
      id, std::move(yaml), std::move(record.calibration), std::move(record.software_version)});
  std::lock_guard lock(mutex_);
  if (const auto it = by_id_.find(id); it != by_id_.end()) return *it->second;
  entries_.push_front(entry);
  by_id_[id] = entries_.begin();
  while (entries_.size() > max_entries_) {
    by_id_.erase(entries_.back()->id);
    entries_.pop_back();
  }
  return entry;
}

std::shared_ptr<const CachedCalibration> CalibrationCache::Find(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it = by_id_.find(id);
  if (it == by_id_.end()) return nullptr;
  entries_.splice(entries_.begin(), entries_, it->second);  // most recently used
  return *it->second;
}

std::size_t CalibrationCache::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

}  // namespace bsls::processing
