// Malformed requests get INVALID_ARGUMENT with a message, on both services.
//
// gRPC C++ parses a request before any handler runs and sends the parser's
// status as the call's: for protobuf, INTERNAL with
// InitializationErrorString(), which is empty for proto3 (a handler on the
// callback API: UNIMPLEMENTED with no message). A caller that sent bytes
// that are not the message was told "internal error" without a word of
// why. The generated code parses every unary request as a
// protobuf::MessageLite (the same traits as the client's replies), so the
// parse itself cannot be given another status without rewriting the
// services on the generic API; a server interceptor can: it sees that no
// request came out of the parse (POST_RECV_MESSAGE with no message) and
// rewrites the status about to be sent (PRE_SEND_STATUS).
//
// Only methods that take one request (unary, server-streaming) are
// rewritten: in a request stream, the sync API shows a malformed message
// to the handler as the stream's end, like a client's half-close, and the
// handler's own status stands.
//
// Thread-safety: the interceptors are per call.
#ifndef BSLS_RPC_MALFORMED_REQUESTS_H_
#define BSLS_RPC_MALFORMED_REQUESTS_H_

namespace grpc {
class ServerBuilder;
}

namespace bsls::rpc {

// Makes `builder`'s server answer a request that does not parse as its
// method's request type with INVALID_ARGUMENT "request: the bytes received
// are not a <type> message" instead of INTERNAL (or UNIMPLEMENTED) with an
// empty message.
// Replaces any interceptors set on `builder` before.
void ReportMalformedRequests(grpc::ServerBuilder& builder);

}  // namespace bsls::rpc

#endif  // BSLS_RPC_MALFORMED_REQUESTS_H_
