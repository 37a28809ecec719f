// The sealed record of a capture's processing (record.json, stored with the
// result files): what went in (the frames by SHA-256, the calibrations by
// id), what came out (every result file by SHA-256, each call's result) and
// who did it (the processing replica and both programs' versions). The
// store writes it from its own copy of the capture's metadata, so the
// record cannot disagree with the capture it seals.
//
// Thread-safety: pure functions.
#ifndef BSLS_STORE_PROVENANCE_H_
#define BSLS_STORE_PROVENANCE_H_

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bsls/store/capture.h"

namespace bsls::store {

// The record's file name among a capture's result files (reserved).
inline constexpr char kRecordFileName[] = "record.json";

// Where a capture's results came from, as the processing queue knows it.
struct ProcessingProvenance {
  std::string call;                                 // the processing service's method
  std::map<std::string, std::string> calibrations;  // side -> the calibration's id ("sha256:...")
  std::vector<nlohmann::json> results;              // each call's result (WorkResult as JSON)
  std::string replica;                              // the replica that did the work
  std::string processing_software_version;
  std::string daemon_software_version;
};

// record.json's text for the results of `capture`, whose files (name -> hex
// SHA-256, the record itself not among them) are `file_sha256`.
std::string ProvenanceRecord(const CaptureInfo& capture, const ProcessingProvenance& provenance,
                             const std::map<std::string, std::string>& file_sha256);

}  // namespace bsls::store

#endif  // BSLS_STORE_PROVENANCE_H_
