#include "bsls/rpc/server_limits.h"

#include <grpcpp/server_builder.h>
#include <malloc.h>

namespace bsls::rpc {

const std::vector<LimitKey<ConnectionLimits>>& ConnectionLimitKeys() {
  static const std::vector<LimitKey<ConnectionLimits>> keys = {
      {"max_connections", &ConnectionLimits::max_connections, 1, 65536},
      {"max_connections_per_user", &ConnectionLimits::max_connections_per_user, 1, 65536},
      {"max_tcp_connections", &ConnectionLimits::max_tcp_connections, 1, 65536},
      {"max_tcp_connections_per_peer", &ConnectionLimits::max_tcp_connections_per_peer, 1, 65536}};
  return keys;
}

const std::vector<LimitKey<Http2Limits>>& Http2LimitKeys() {
  constexpr int kDay = 24 * 3600 * 1000;
  static const std::vector<LimitKey<Http2Limits>> keys = {
      {"keepalive_time_ms", &Http2Limits::keepalive_time_ms, 1000, kDay},
      {"keepalive_timeout_ms", &Http2Limits::keepalive_timeout_ms, 1000, 600000},
      {"min_ping_interval_ms", &Http2Limits::min_ping_interval_ms, 1000, kDay},
      {"max_ping_strikes", &Http2Limits::max_ping_strikes, 1, 100},
      {"max_connection_idle_ms", &Http2Limits::max_connection_idle_ms, 100, kDay},
      {"max_concurrent_streams", &Http2Limits::max_concurrent_streams, 1, 10000},
      {"handshake_timeout_ms", &Http2Limits::handshake_timeout_ms, 100, 120000}};
  return keys;
}

const std::vector<LimitKey<Http2GuardLimits>>& Http2GuardLimitKeys() {
  static const std::vector<LimitKey<Http2GuardLimits>> keys = {
      {"guard_frames_per_second", &Http2GuardLimits::frames_per_second, 1, 1000000},
      {"guard_burst", &Http2GuardLimits::burst, 1, 1000000},
      {"guard_total_frames_per_second", &Http2GuardLimits::total_frames_per_second, 1, 1000000},
      {"guard_total_burst", &Http2GuardLimits::total_burst, 1, 1000000}};
  return keys;
}

std::string Http2GuardLimitsError(const Http2GuardLimits& guard) {
  if (guard.frames_per_second > guard.total_frames_per_second)
    return "listen.guard_frames_per_second is above listen.guard_total_frames_per_second";
  if (guard.burst > guard.total_burst)
    return "listen.guard_burst is above listen.guard_total_burst";
  return {};
}

void ApplyHttp2Limits(const Http2Limits& limits, grpc::ServerBuilder& builder) {
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, limits.keepalive_time_ms);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, limits.keepalive_timeout_ms);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
                             limits.min_ping_interval_ms);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PING_STRIKES, limits.max_ping_strikes);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, limits.max_connection_idle_ms);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, limits.max_concurrent_streams);
  builder.AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, limits.handshake_timeout_ms);
}

void TuneAllocator() {
  ::mallopt(M_MMAP_THRESHOLD, 256 << 10);
  ::mallopt(M_ARENA_MAX, 2);
}

void ReturnFreedMemory() { ::malloc_trim(0); }

}  // namespace bsls::rpc
