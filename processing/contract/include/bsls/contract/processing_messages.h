// The processing contract's messages (bsls/v1/processing.proto) as the
// processing library's types and back: sides, decode and surface options,
// the join, measurement plans and the per-side summaries. Every enum number
// is checked against its .proto (proto3 keeps numbers it does not define).
//
// Thread-safety: pure functions.
#ifndef BSLS_CONTRACT_PROCESSING_MESSAGES_H_
#define BSLS_CONTRACT_PROCESSING_MESSAGES_H_

#include <string>

#include "bsls/contract/message_error.h"
#include "bsls/measurement/plan.h"
#include "bsls/pattern/brick_pattern.h"
#include "bsls/reconstruction/side_pipeline.h"
#include "bsls/session/session.h"
#include "bsls/v1/processing.pb.h"

namespace bsls::contract {

// The side a message names; MessageError naming `field` for any value but
// SIDE_LEFT and SIDE_RIGHT.
pattern::Side SideOf(v1::Side side, const std::string& field);
// The contract's name of a side.
v1::Side ToProto(pattern::Side side);

// One side's decode and surface parameters from a request's options;
// MessageError naming the field for an undefined enum number or a chain
// the decode options cannot run.
reconstruction::SidePipelineParams SideParams(const v1::DecodeOptions& decode,
                                              const v1::SurfaceOptions& surface);

// How a session's sides are joined; MessageError for an undefined number.
session::JoinMode JoinModeOf(v1::ReconstructSessionRequest::Join join);

// The figures a request asks for; MessageError naming the figure when there
// are more than `max_figures`, a distance has other than two points, the
// reference is undefined or the plan is not valid (measurement::plan.h).
measurement::MeasurementPlan PlanOf(const v1::MeasurementPlan& m, int max_figures);
// The message of a plan: PlanOf(ToProto(plan), n) == plan for a valid plan.
v1::MeasurementPlan ToProto(const measurement::MeasurementPlan& plan);

// The counts of one side's decode and surface, as the result reports them.
void FillSide(const reconstruction::SideOutcome& outcome, pattern::Side side, v1::SideSummary* out);

}  // namespace bsls::contract

#endif  // BSLS_CONTRACT_PROCESSING_MESSAGES_H_
