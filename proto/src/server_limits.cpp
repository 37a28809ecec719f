#include "bsls/rpc/server_limits.h"

#include <grpcpp/server_builder.h>
#include <malloc.h>

#include "bsls/io/config_document.h"

namespace bsls::rpc {

const std::set<std::string>& Http2LimitKeys() {
  static const std::set<std::string> keys = {"keepalive_time_ms",      "keepalive_timeout_ms",
                                             "min_ping_interval_ms",   "max_ping_strikes",
                                             "max_connection_idle_ms", "max_concurrent_streams"};
  return keys;
}

void ReadHttp2Limits(const YAML::Node& node, const std::string& where, Http2Limits& out) {
  if (!node) return;
  constexpr int kDay = 24 * 3600 * 1000;
  io::ReadKeyInRange(node, where, "keepalive_time_ms", out.keepalive_time_ms, 1000, kDay);
  io::ReadKeyInRange(node, where, "keepalive_timeout_ms", out.keepalive_timeout_ms, 1000, 600000);
  io::ReadKeyInRange(node, where, "min_ping_interval_ms", out.min_ping_interval_ms, 1000, kDay);
  io::ReadKeyInRange(node, where, "max_ping_strikes", out.max_ping_strikes, 1, 100);
  io::ReadKeyInRange(node, where, "max_connection_idle_ms", out.max_connection_idle_ms, 100, kDay);
  io::ReadKeyInRange(node, where, "max_concurrent_streams", out.max_concurrent_streams, 1, 10000);
}

void DumpHttp2Limits(YAML::Emitter& out, const Http2Limits& limits) {
  out << YAML::Key << "keepalive_time_ms" << YAML::Value << limits.keepalive_time_ms;
  out << YAML::Key << "keepalive_timeout_ms" << YAML::Value << limits.keepalive_timeout_ms;
  out << YAML::Key << "min_ping_interval_ms" << YAML::Value << limits.min_ping_interval_ms;
  out << YAML::Key << "max_ping_strikes" << YAML::Value << limits.max_ping_strikes;
  out << YAML::Key << "max_connection_idle_ms" << YAML::Value << limits.max_connection_idle_ms;
  out << YAML::Key << "max_concurrent_streams" << YAML::Value << limits.max_concurrent_streams;
}

void ApplyHttp2Limits(const Http2Limits& limits, grpc::ServerBuilder& builder) {
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, limits.keepalive_time_ms);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, limits.keepalive_timeout_ms);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
                             limits.min_ping_interval_ms);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PING_STRIKES, limits.max_ping_strikes);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, limits.max_connection_idle_ms);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, limits.max_concurrent_streams);
}

void TuneAllocator() {
  ::mallopt(M_MMAP_THRESHOLD, 256 << 10);
  ::mallopt(M_ARENA_MAX, 2);
}

void ReturnFreedMemory() { ::malloc_trim(0); }

}  // namespace bsls::rpc
