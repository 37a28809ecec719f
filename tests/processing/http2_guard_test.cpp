// rpc::Http2Guard between a client and a stand-in for gRPC (the end of the
// pair the guard returns): bytes pass both ways unchanged; the frames that
// make the server work (here PING) pass no faster than the budget, DATA
// passes as it comes; when either side closes, the other sees the end.
// The daemon under a real flood: BslsdHttp2Flood.* (bslsd_http2_flood_test).
#include "bsls/rpc/http2_guard.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include "bsls/testing/http2_flood.h"
#include "bsls/testing/raw_connections.h"

namespace bsls::rpc {
namespace {

using std::chrono::milliseconds;
namespace h2 = testing::http2;
using testing::ReadFor;

// A guarded connection: the client's socket and gRPC's end.
struct Guarded {
  int client = -1;
  int server = -1;
  ~Guarded() {
    if (client >= 0) ::close(client);
    if (server >= 0) ::close(server);
  }
};

// A client connection handed to `guard`.
void Connect(Http2Guard& guard, Guarded* out) {
  int pair[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, pair), 0);
  out->client = pair[0];
  std::string error;
  ASSERT_TRUE(guard.Guard(
      pair[1], [out](int fd, const std::string&) { out->server = fd; }, &error))
      << error;
  ASSERT_GE(out->server, 0);
}

TEST(Http2Guard, BytesPassBothWaysUnchanged) {
  std::string error;
  auto guard = Http2Guard::Create({}, &error);
  ASSERT_NE(guard, nullptr) << error;
  guard->Start();
  Guarded link;
  Connect(*guard, &link);
  const std::string up = h2::Preface() + h2::CallHeaders(1, "/a.B/C") + h2::Ping(7);
  ASSERT_TRUE(testing::SendAll(link.client, up));
  EXPECT_EQ(ReadFor(link.server, 300), up);
  const std::string down = h2::Frame(h2::kSettings, 0, 0, "") + std::string(100000, 'x');
  ASSERT_TRUE(testing::SendAll(link.server, down));
  EXPECT_EQ(ReadFor(link.client, 500), down);
  EXPECT_EQ(guard->relayed(), 1u);
  EXPECT_EQ(guard->throttled(), 0u);
}

// 1000 PINGs at once with a budget of 50 a second after a burst of 50: about
// 50 + 50 * 0.5 pass in the first half second, the rest wait. 1000 DATA
// frames at once pass at once.
TEST(Http2Guard, CostlyFramesPassAtTheBudgetsRateAndDataAsItComes) {
  Http2GuardLimits limits;
  limits.frames_per_second = 50;
  limits.burst = 50;
  std::string error;
  auto guard = Http2Guard::Create(limits, &error);
  ASSERT_NE(guard, nullptr) << error;
  guard->Start();
  Guarded link;
  Connect(*guard, &link);
  const std::string ping = h2::Ping(1);
  std::string pings;
  for (int i = 0; i < 1000; ++i) pings += ping;
  ASSERT_TRUE(testing::SendAll(link.client, h2::Preface() + pings));
  const std::size_t passed =
      (ReadFor(link.server, 500).size() - h2::Preface().size()) / ping.size();
  EXPECT_GE(passed, 50u);
  EXPECT_LE(passed, 50u + 50u / 2 + 10u) << "the budget did not hold back the flood";
  EXPECT_GE(guard->throttled(), 1u);

  Guarded data_link;
  Connect(*guard, &data_link);
  std::string data = h2::Preface();
  for (int i = 0; i < 1000; ++i) data += h2::Frame(0x0 /*DATA*/, 0, 1, "0123456789");
  ASSERT_TRUE(testing::SendAll(data_link.client, data));
  EXPECT_EQ(ReadFor(data_link.server, 500), data) << "DATA frames were held back";
}

// The budget for all connections together holds when each has its own left.
TEST(Http2Guard, TheTotalBudgetHoldsAcrossConnections) {
  Http2GuardLimits limits;
  limits.total_frames_per_second = 20;
  limits.total_burst = 20;
  std::string error;
  auto guard = Http2Guard::Create(limits, &error);
  ASSERT_NE(guard, nullptr) << error;
  guard->Start();
  Guarded a, b;
  Connect(*guard, &a);
  Connect(*guard, &b);
  std::string pings = h2::Preface();
  for (int i = 0; i < 100; ++i) pings += h2::Ping(2);
  ASSERT_TRUE(testing::SendAll(a.client, pings));
  ASSERT_TRUE(testing::SendAll(b.client, pings));
  std::thread read_a([&] { pings = ReadFor(a.server, 500); });
  const std::string from_b = ReadFor(b.server, 500);
  read_a.join();
  const std::size_t passed =
      (pings.size() + from_b.size() - 2 * h2::Preface().size()) / h2::Ping(2).size();
  EXPECT_GE(passed, 20u);
  EXPECT_LE(passed, 20u + 20u / 2 + 6u);
}

// gRPC closing its end closes the client's, and the other way round.
TEST(Http2Guard, EitherSideClosingEndsTheOther) {
  std::string error;
  auto guard = Http2Guard::Create({}, &error);
  ASSERT_NE(guard, nullptr) << error;
  guard->Start();
  Guarded by_server, by_client;
  Connect(*guard, &by_server);
  Connect(*guard, &by_client);
  ::close(by_server.server);
  by_server.server = -1;
  bool ended = false;
  ReadFor(by_server.client, 1000, &ended);
  EXPECT_TRUE(ended) << "the client still connected after gRPC closed";
  ::close(by_client.client);
  by_client.client = -1;
  ReadFor(by_client.server, 1000, &ended);
  EXPECT_TRUE(ended) << "gRPC's end still open after the client closed";
  const auto until = std::chrono::steady_clock::now() + milliseconds(1000);
  while (guard->relayed() > 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(milliseconds(10));
  EXPECT_EQ(guard->relayed(), 0u);
}

// A client that connects and never sends the HTTP/2 preface is closed at
// the handshake timeout (the Unix socket and plain loopback TCP: gRPC takes
// these connections from a descriptor and times no handshake itself); one
// that sends it in time stays.
TEST(Http2Guard, AClientWithoutAPrefaceIsClosedAtTheHandshakeTimeout) {
  std::string error;
  auto guard = Http2Guard::Create({}, &error, nullptr, /*handshake_timeout_ms=*/300);
  ASSERT_NE(guard, nullptr) << error;
  guard->Start();
  Guarded silent, speaking;
  Connect(*guard, &silent);
  Connect(*guard, &speaking);
  ASSERT_TRUE(testing::SendAll(speaking.client, h2::Preface()));
  const auto start = std::chrono::steady_clock::now();
  bool ended = false;
  ReadFor(silent.client, 3000, &ended);
  const auto waited =
      std::chrono::duration_cast<milliseconds>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(ended) << "a silent client kept its connection 3 s past a 300 ms timeout";
  EXPECT_GE(waited, 200);
  EXPECT_LE(waited, 1500);
  EXPECT_EQ(guard->refused(), 1u);
  ReadFor(speaking.client, 200, &ended);
  EXPECT_FALSE(ended) << "a client that sent its preface was closed";
  EXPECT_EQ(guard->relayed(), 1u);
}

}  // namespace
}  // namespace bsls::rpc
