#include "bsls/reconstruction/side_pipeline.h"

#include <stdexcept>

namespace bsls::reconstruction {

bool SidePipelineParams::IsValid(std::string* error) const {
  if (decode.q_offset) {
    if (error)
      *error = "SidePipelineParams.decode.q_offset must be unset (the calibration fixes q)";
    return false;
  }
  std::string why;
  if (!decoder::ChainFor(chain, decode, &why)) {
    if (error) *error = "SidePipelineParams.chain: " + why;
    return false;
  }
  return decode.IsValid(error) && reconstruction.IsValid(error) && rows.IsValid(error) &&
         islands.IsValid(error);
}

SideOutcome ProcessSide(const cv::Mat& grey, pattern::Side side, const SideGeometry& geometry,
                        const SidePipelineParams& params, const Cancellation& cancel) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument("ProcessSide: " + error);
  const auto* calibration = std::get_if<const calibration::SideCalibration*>(&geometry);
  if (calibration) {
    const calibration::SideCalibration& cal = **calibration;
    if (cal.side != side)
      throw std::invalid_argument(
          "the calibration is of the " + std::string(pattern::ToString(cal.side)) +
          " side, the frame of the " + std::string(pattern::ToString(side)));
    if (cal.width != grey.cols || cal.height != grey.rows)
      throw std::invalid_argument("the calibration is for " + std::to_string(cal.width) + "x" +
                                  std::to_string(cal.height) + " frames, the frame is " +
                                  std::to_string(grey.cols) + "x" + std::to_string(grey.rows));
  }

  // The chain: the one named, else the track chain (the skeleton chain
  // where `decode` asks for its own options).
  decoder::DecodeParams decode = params.decode;
  if (calibration) decode.geometry = LabelGeometryOfCalibration(**calibration, params.islands);
  decode.chain = decoder::DecodeChain::kTracks;
  decode.chain = *decoder::ChainFor(params.chain, decode, nullptr);  // checked by IsValid
  SideOutcome outcome;
  outcome.decode = decoder::Decode(grey, side, decode, cancel);
  if (!outcome.decode.ok) return outcome;
  if (calibration) {
    if (const auto offset =
            SlideRowOffset(outcome.decode, **calibration, &outcome.rows_note, params.rows)) {
      MakeRowsAbsolute(*offset, &outcome.decode);
      outcome.rows_note.clear();
    }
  }
  if (!params.reconstruct || std::holds_alternative<std::monostate>(geometry)) return outcome;

  TriangulationModel model;
  if (calibration) {
    model = ModelOfCalibration(**calibration, params.planes);
  } else {
    model.side = side;
    model.geometry = std::get<GeometricSetupParams>(geometry);
  }
  cancel.ThrowIfRequested("the decode");
  outcome.surface = Reconstruct(outcome.decode, model, params.reconstruction, &outcome.report);
  return outcome;
}

}  // namespace bsls::reconstruction
