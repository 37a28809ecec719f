// What both services (bslsd, bsls-processd) do the same way to stay within
// bounds whatever their callers send: the connections their Unix socket
// takes at once, HTTP/2 keep-alive, ping and stream limits set on the gRPC
// server through channel arguments, both under the same configuration keys
// of `listen:` (named here with their ranges; each service's configuration
// reads them with bsls::ReadKeysInRange), and the allocator discipline
// that gives memory back after a burst of requests or a flood.
//
// Thread-safety: the key tables and ApplyHttp2Limits are pure; TuneAllocator
// is called once, from main, before any thread starts; ReturnFreedMemory is
// safe from any thread.
#ifndef BSLS_RPC_SERVER_LIMITS_H_
#define BSLS_RPC_SERVER_LIMITS_H_

#include <string>
#include <vector>

#include "bsls/rpc/http2_guard.h"

namespace grpc {
class ServerBuilder;
}

namespace bsls::rpc {

// Connections open at once (handed to gRPC and not yet closed by it): of a
// service's Unix socket in all and per peer uid (rpc::UnixAcceptor), of its
// TCP listener in all and per peer address (rpc::TcpAcceptor); a connection
// beyond a limit is closed as soon as it is accepted, so that one user or
// one machine cannot take every descriptor.
struct ConnectionLimits {
  int max_connections = 128;              // Unix socket, in all
  int max_connections_per_user = 32;      // Unix socket, per peer uid
  int max_tcp_connections = 128;          // TCP, in all
  int max_tcp_connections_per_peer = 32;  // TCP, per peer address
};

// The HTTP/2 limits of one server, per connection. Times in milliseconds.
struct Http2Limits {
  // The server pings a connection that sent nothing for this long...
  int keepalive_time_ms = 60000;
  // ...and closes it when the ping is not answered within this.
  int keepalive_timeout_ms = 20000;
  // A client's pings closer together than this while no data flows count
  // as strikes (gRPC's own default is 5 minutes; ours allow clients that
  // keep their connection alive every 10 s)...
  int min_ping_interval_ms = 10000;
  // ...and after this many strikes the connection is closed (GOAWAY
  // ENHANCE_YOUR_CALM): a ping flood costs one connection, not the server.
  int max_ping_strikes = 2;
  // A connection without any call for this long is closed (the client
  // reconnects when it needs to): idle connections do not pile up.
  int max_connection_idle_ms = 300000;
  // Calls open at once on one connection; more wait for one to end.
  int max_concurrent_streams = 100;
  // A connection whose handshake (TLS, HTTP/2 preface) is not done within
  // this is closed: a peer that connects and sends nothing holds its
  // descriptor and connection slot this long at most (gRPC's default: 120 s).
  int handshake_timeout_ms = 10000;
};

// One integer configuration key under `listen:` of a limits struct: its
// name, the member it sets and the range a value must lie in.
template <typename Limits>
struct LimitKey {
  const char* name;
  int Limits::*member;
  int min;
  int max;
};

// The keys of ConnectionLimits, in the order --check-config prints them.
const std::vector<LimitKey<ConnectionLimits>>& ConnectionLimitKeys();

// The keys of Http2Limits, in the order --check-config prints them.
const std::vector<LimitKey<Http2Limits>>& Http2LimitKeys();

// The keys of Http2GuardLimits (the plaintext relay's frame budgets), in the
// order --check-config prints them.
const std::vector<LimitKey<Http2GuardLimits>>& Http2GuardLimitKeys();

// Why `guard` cannot be used (a connection's budget above the total), or
// empty when it can; the keys are named as under `listen:`.
std::string Http2GuardLimitsError(const Http2GuardLimits& guard);

// Sets `limits` on `builder` as gRPC channel arguments (keep-alive, ping
// strikes, idle connections, concurrent streams, handshake deadline).
void ApplyHttp2Limits(const Http2Limits& limits, grpc::ServerBuilder& builder);

// Sets glibc's allocator for a long-running server: blocks of 256 KiB and
// more (frames, meshes, artifacts) are mapped and unmapped on their own
// instead of growing the heaps, and two arenas instead of one per core and
// thread keep freed blocks from piling up in idle ones. Call once from main
// before any thread starts.
void TuneAllocator();

// Hands freed heap memory back to the system (malloc_trim): called after
// work and periodically, so resident memory returns to its level after a
// burst or a flood.
void ReturnFreedMemory();

}  // namespace bsls::rpc

#endif  // BSLS_RPC_SERVER_LIMITS_H_
