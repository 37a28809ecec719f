#include "bsls/store/provenance.h"

namespace bsls::store {

std::string ProvenanceRecord(const CaptureInfo& capture, const ProcessingProvenance& provenance,
                             const std::map<std::string, std::string>& file_sha256) {
  nlohmann::json frames = nlohmann::json::array();
  for (const StoredFrameInfo& f : capture.frames)
    frames.push_back({{"camera", framestore::ToString(f.camera)},
                      {"width", f.width},
                      {"height", f.height},
                      {"sha256", f.sha256}});
  nlohmann::json files = nlohmann::json::object();
  for (const auto& [name, sha256] : file_sha256) files[name] = sha256;
  nlohmann::json calibrations = nlohmann::json::object();
  for (const auto& [side, id] : provenance.calibrations) calibrations[side] = id;
  const nlohmann::json record = {
      {"format", "bsls-processing-record"},
      {"format_version", 1},
      {"capture_id", capture.id.str()},
      {"session_id", capture.session_id},
      {"patient_reference", capture.patient_reference},
      {"side", ToString(capture.side)},
      {"frames", frames},
      {"calibrations", calibrations},
      {"call", provenance.call},
      {"results", provenance.results},
      {"files", files},
      {"processing_software_version", provenance.processing_software_version},
      {"replica", provenance.replica},
      {"daemon_software_version", provenance.daemon_software_version}};
  return record.dump(2) + "\n";
}

}  // namespace bsls::store
