// bsls-processd's configuration: defaults, overrides, and the network rules
// (mutual TLS for TCP; plain TCP only on loopback when asked for).
#include <gtest/gtest.h>

#include "bsls/rpc/tls.h"
#include "config.h"

namespace bsls::processd {
namespace {

std::string ErrorOf(const std::vector<std::string>& overrides) {
  try {
    LoadConfig(std::nullopt, overrides);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ProcessdConfig, DefaultsServeTheLocalSocketOnly) {
  const Config c = LoadConfig(std::nullopt, {});
  EXPECT_EQ(c.listen.unix_socket, "/run/bsls-processd/processd.sock");
  EXPECT_TRUE(c.listen.tcp.empty());
  EXPECT_GE(Workers(c), 1);
  EXPECT_EQ(Queue(c), 2 * Workers(c));
}

TEST(ProcessdConfig, TcpIsMutualTlsUnlessPlainLoopback) {
  EXPECT_NE(ErrorOf({"listen.tcp=0.0.0.0:7000"}).find("mutual TLS only"), std::string::npos);
  EXPECT_NE(ErrorOf({"listen.tcp=10.1.2.3:7000", "listen.plaintext_loopback=true"})
                .find("only for loopback"),
            std::string::npos);
  EXPECT_EQ(ErrorOf({"listen.tcp=127.0.0.1:0", "listen.plaintext_loopback=true"}), "");
  EXPECT_EQ(ErrorOf({"listen.tcp=\"[::1]:0\"", "listen.plaintext_loopback=true"}), "");
  EXPECT_EQ(ErrorOf({"listen.tcp=localhost:7000", "listen.plaintext_loopback=true"}), "");
}

TEST(ProcessdConfig, ErrorsNameTheKey) {
  EXPECT_NE(ErrorOf({"workers=-3"}).find("workers"), std::string::npos);
  EXPECT_NE(ErrorOf({"listen.tpc=1"}).find("listen.tpc"), std::string::npos);
  EXPECT_NE(ErrorOf({"log_level=loud"}).find("log_level"), std::string::npos);
  EXPECT_NE(ErrorOf({"listen.unix_socket=\"\""}).find("listen.unix_socket or listen.tcp"),
            std::string::npos);
  EXPECT_NE(ErrorOf({"scratch_dir=/nonexistent/x"}).find("scratch_dir"), std::string::npos);
}

// The HTTP/2 and connection limits have defaults, are read under
// listen: and are bounded (a key out of range is named).
TEST(ProcessdConfig, Http2LimitsHaveBoundedDefaults) {
  const Config defaults = LoadConfig(std::nullopt, {});
  EXPECT_EQ(defaults.listen.http2.max_ping_strikes, 2);
  EXPECT_EQ(defaults.listen.http2.max_connection_idle_ms, 300000);
  const Config c = LoadConfig(
      std::nullopt, {"listen.max_connection_idle_ms=1000", "listen.max_concurrent_streams=8"});
  EXPECT_EQ(c.listen.http2.max_connection_idle_ms, 1000);
  EXPECT_EQ(c.listen.http2.max_concurrent_streams, 8);
  EXPECT_NE(ErrorOf({"listen.max_ping_strikes=0"}).find("listen.max_ping_strikes"),
            std::string::npos);
  EXPECT_NE(ErrorOf({"listen.min_ping_interval_ms=1"}).find("listen.min_ping_interval_ms"),
            std::string::npos);
  EXPECT_NE(ErrorOf({"listen.max_concurrent_streams=100000"}).find("max_concurrent_streams"),
            std::string::npos);
  EXPECT_NE(Dump(c).find("max_connection_idle_ms: 1000"), std::string::npos) << Dump(c);
  EXPECT_EQ(defaults.listen.connections.max_connections, 128);
  EXPECT_EQ(defaults.listen.connections.max_connections_per_user, 32);
  EXPECT_NE(ErrorOf({"listen.max_connections_per_user=200"}).find("max_connections_per_user"),
            std::string::npos);
}

// The Unix socket's frame budgets (rpc::Http2Guard) are keys of `listen:`,
// bounded, and a connection's budget may not exceed the total.
TEST(ProcessdConfig, GuardBudgetsAreBoundedKeys) {
  const Config defaults = LoadConfig(std::nullopt, {});
  EXPECT_EQ(defaults.listen.guard.frames_per_second, 200);
  EXPECT_EQ(defaults.listen.guard.total_burst, 4000);
  const Config c = LoadConfig(
      std::nullopt, {"listen.guard_frames_per_second=50", "listen.guard_total_burst=500"});
  EXPECT_EQ(c.listen.guard.frames_per_second, 50);
  EXPECT_EQ(c.listen.guard.total_burst, 500);
  EXPECT_NE(Dump(c).find("guard_frames_per_second: 50"), std::string::npos) << Dump(c);
  EXPECT_NE(ErrorOf({"listen.guard_burst=0"}).find("listen.guard_burst"), std::string::npos);
  EXPECT_NE(
      ErrorOf({"listen.guard_frames_per_second=3000"})
          .find("listen.guard_frames_per_second is above listen.guard_total_frames_per_second"),
      std::string::npos);
  EXPECT_NE(ErrorOf({"listen.guard_burst=5000"}).find("listen.guard_total_burst"),
            std::string::npos);
}

TEST(RpcTargets, LoopbackIsRecognised) {
  EXPECT_TRUE(rpc::IsLoopbackTarget("127.0.0.1:7000"));
  EXPECT_TRUE(rpc::IsLoopbackTarget("ipv4:127.0.0.1:7001,127.0.0.2:7002"));
  EXPECT_TRUE(rpc::IsLoopbackTarget("[::1]:7000"));
  EXPECT_TRUE(rpc::IsLoopbackTarget("dns:///localhost:7000"));
  EXPECT_FALSE(rpc::IsLoopbackTarget("ipv4:127.0.0.1:7001,10.0.0.2:7002"));
  EXPECT_FALSE(rpc::IsLoopbackTarget("processd.clinic:7000"));
  EXPECT_FALSE(rpc::IsLoopbackTarget("128.0.0.1:7000"));
  EXPECT_TRUE(rpc::IsUnixTarget("unix:/run/x.sock"));
}

}  // namespace
}  // namespace bsls::processd
