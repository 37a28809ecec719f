// rpc::Http2Guard ending mutual TLS (the services' TCP listeners, issue 26):
// a client with a certificate of the CA is handed over with its common
// name and its bytes pass both ways; a client without one, or with one of
// another CA, or one that never shakes hands, is closed and never handed
// over; the frame budget holds inside TLS as on plaintext. The client is
// OpenSSL through bsls/testing/tls_tunnel.h, the listening socket the
// test's own. The services over TLS: Bslsd.TcpServesOnlyMutualTlsCallers*,
// ProcessdServer.TcpServesOnlyMutualTlsClientsOfItsCa, BslsdHttp2Guard.*.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bsls/rpc/http2_guard.h"
#include "bsls/rpc/tls_session.h"
#include "bsls/testing/certificates.h"
#include "bsls/testing/http2_flood.h"
#include "bsls/testing/raw_connections.h"
#include "bsls/testing/tls_tunnel.h"

namespace bsls::rpc {
namespace {

using std::chrono::milliseconds;
namespace fs = std::filesystem;
namespace h2 = testing::http2;
using testing::ReadFor;

// A loopback listening socket whose connections the test hands to a guard.
class Listener {
 public:
  Listener() {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&address), length) == 0 && ::listen(fd_, 8) == 0 &&
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &length) == 0)
      port_ = ntohs(address.sin_port);
  }
  ~Listener() { ::close(fd_); }
  int port() const { return port_; }
  // The next connection, made non-blocking as the acceptor makes them; -1
  // when none comes within a second.
  int Accept() const {
    pollfd wait{fd_, POLLIN, 0};
    if (::poll(&wait, 1, 1000) != 1) return -1;
    return ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
  }

 private:
  int fd_ = -1;
  int port_ = 0;
};

// What the guard handed over: gRPC's ends and the names they came with.
struct HandedOver {
  std::mutex mutex;
  std::vector<std::pair<int, std::string>> connections;
  ~HandedOver() {
    for (const auto& [fd, name] : connections) ::close(fd);
  }
  Http2Guard::HandOver Taker() {
    return [this](int fd, const std::string& name) {
      std::lock_guard lock(mutex);
      connections.emplace_back(fd, name);
    };
  }
  std::size_t size() {
    std::lock_guard lock(mutex);
    return connections.size();
  }
};

// A CA with a server certificate and a client certificate "station", and a
// second CA with its own "station".
class GuardEndingTls : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path dir =
        fs::path(::testing::TempDir()) / ("guard_tls_" + std::to_string(::getpid()));
    testing::TestPki pki(dir, "clinic");
    server_ = pki.Issue("localhost", true);
    station_ = pki.Issue("station");
    testing::TestPki other(dir, "other");
    stranger_ = other.Issue("station");
    ASSERT_TRUE(pki.ok() && other.ok()) << "openssl could not make the test certificates";
    ca_ = pki.ca();
  }

  // A started guard ending TLS with the server certificate, clients of the clinic's CA.
  std::unique_ptr<Http2Guard> MakeGuard(const Http2GuardLimits& limits, int handshake_ms = 5000) {
    std::string error;
    auto guard = Http2Guard::Create(
        limits, &error, TlsServerContext::Create({ca_, server_.certificate, server_.key}),
        handshake_ms);
    EXPECT_NE(guard, nullptr) << error;
    if (guard) guard->Start();
    return guard;
  }

  // A client of `tunnels` connected through listener_ and given to `guard`,
  // whose hand-over handed_ takes: the client's plaintext end, or -1 when
  // its handshake failed.
  int Open(Http2Guard& guard, testing::TlsTunnels& tunnels) {
    std::thread accept([&] {
      std::string error;
      EXPECT_TRUE(guard.Guard(listener_.Accept(), handed_.Taker(), &error)) << error;
    });
    const int client = tunnels.Open(listener_.port());
    accept.join();
    return client;
  }

  // Waits up to a second for `done`.
  template <typename Done>
  static bool WaitFor(Done done) {
    const auto until = std::chrono::steady_clock::now() + milliseconds(1000);
    while (!done() && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(milliseconds(10));
    return done();
  }

  testing::PemFiles server_, station_, stranger_;
  fs::path ca_;
  HandedOver handed_;  // what the guards of the test handed over
  Listener listener_;  // where the test's clients connect
};

TEST_F(GuardEndingTls, AVerifiedClientIsHandedOverWithItsNameAndItsBytesPassBothWays) {
  auto guard = MakeGuard({});
  ASSERT_NE(guard, nullptr);
  testing::TlsTunnels tunnels(station_, ca_);
  ASSERT_TRUE(tunnels.ok());
  const int client = Open(*guard, tunnels);
  ASSERT_GE(client, 0) << "the handshake failed";
  ASSERT_TRUE(WaitFor([&] { return handed_.size() == 1; }));
  const auto [server, name] = handed_.connections[0];
  EXPECT_EQ(name, "station");
  const std::string up = h2::Preface() + h2::CallHeaders(1, "/a.B/C") + h2::Ping(7);
  ASSERT_TRUE(testing::SendAll(client, up));
  EXPECT_EQ(ReadFor(server, 500), up);
  const std::string down = h2::Frame(h2::kSettings, 0, 0, "") + std::string(200000, 'x');
  ASSERT_TRUE(testing::SendAll(server, down));
  EXPECT_EQ(ReadFor(client, 1000), down);
  EXPECT_EQ(guard->refused(), 0u);
  ::close(client);
}

TEST_F(GuardEndingTls, ClientsWithoutACertificateOfTheCaNeverReachGrpc) {
  auto guard = MakeGuard({});
  ASSERT_NE(guard, nullptr);
  testing::TlsTunnels anonymous(testing::PemFiles{}, ca_);
  testing::TlsTunnels stranger(stranger_, ca_);
  for (testing::TlsTunnels* tunnels : {&anonymous, &stranger}) {
    const int client = Open(*guard, *tunnels);
    EXPECT_LT(client, 0) << "a client the CA did not sign got a connection";
    if (client >= 0) ::close(client);
  }
  EXPECT_TRUE(WaitFor([&] { return guard->refused() == 2; })) << guard->refused();
  EXPECT_EQ(handed_.size(), 0u);
  EXPECT_TRUE(WaitFor([&] { return guard->relayed() == 0; }));
}

TEST_F(GuardEndingTls, AClientThatNeverShakesHandsIsClosedAtTheTimeout) {
  auto guard = MakeGuard({}, /*handshake_ms=*/300);
  ASSERT_NE(guard, nullptr);
  const int silent = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(listener_.port()));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(silent, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(guard->Guard(listener_.Accept(), handed_.Taker(), &error)) << error;
  pollfd wait{silent, POLLIN, 0};
  ASSERT_EQ(::poll(&wait, 1, 3000), 1) << "still open 3 s after a 300 ms handshake timeout";
  char byte;
  EXPECT_EQ(::recv(silent, &byte, 1, 0), 0) << "closed, not answered";
  const auto waited =
      std::chrono::duration_cast<milliseconds>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(waited, 250);
  EXPECT_LE(waited, 1500);
  EXPECT_EQ(guard->refused(), 1u);
  EXPECT_EQ(handed_.size(), 0u);
  ::close(silent);
}

// Once the server has stopped taking connections (StopHandingOver, as a
// service drains), a client that finishes its handshake is closed, not
// handed to a server that is going.
TEST_F(GuardEndingTls, NothingIsHandedOverOnceHandingOverStopped) {
  auto guard = MakeGuard({});
  ASSERT_NE(guard, nullptr);
  testing::TlsTunnels tunnels(station_, ca_);
  guard->StopHandingOver();
  const int client = Open(*guard, tunnels);
  if (client >= 0) {
    pollfd wait{client, POLLIN, 0};
    EXPECT_EQ(::poll(&wait, 1, 2000), 1) << "the client was not closed";
    ::close(client);
  }
  EXPECT_TRUE(WaitFor([&] { return guard->relayed() == 0; }));
  EXPECT_EQ(handed_.size(), 0u);
}

// A verified client that never sends the HTTP/2 preface is closed at the
// timeout too, after its hand-over.
TEST_F(GuardEndingTls, AVerifiedClientWithoutAPrefaceIsClosedAtTheTimeout) {
  auto guard = MakeGuard({}, /*handshake_ms=*/500);
  ASSERT_NE(guard, nullptr);
  testing::TlsTunnels tunnels(station_, ca_);
  const int client = Open(*guard, tunnels);
  ASSERT_GE(client, 0);
  EXPECT_TRUE(WaitFor([&] { return handed_.size() == 1; }));
  pollfd wait{client, POLLIN, 0};
  ASSERT_EQ(::poll(&wait, 1, 3000), 1) << "still open 3 s after a 500 ms timeout";
  char byte;
  EXPECT_EQ(::recv(client, &byte, 1, 0), 0);
  EXPECT_EQ(guard->refused(), 1u);
  ::close(client);
}

// 1000 PINGs at once inside TLS with a budget of 50 a second after a burst
// of 50: about 50 + 50 * 0.5 reach gRPC's end in the first half second.
TEST_F(GuardEndingTls, CostlyFramesInsideTlsPassAtTheBudgetsRate) {
  Http2GuardLimits limits;
  limits.frames_per_second = 50;
  limits.burst = 50;
  auto guard = MakeGuard(limits);
  ASSERT_NE(guard, nullptr);
  testing::TlsTunnels tunnels(station_, ca_);
  const int client = Open(*guard, tunnels);
  ASSERT_GE(client, 0);
  ASSERT_TRUE(WaitFor([&] { return handed_.size() == 1; }));
  const std::string ping = h2::Ping(1);
  std::string pings = h2::Preface();
  for (int i = 0; i < 1000; ++i) pings += ping;
  ASSERT_TRUE(testing::SendAll(client, pings));
  const std::size_t passed =
      (ReadFor(handed_.connections[0].first, 500).size() - h2::Preface().size()) / ping.size();
  EXPECT_GE(passed, 50u);
  EXPECT_LE(passed, 50u + 50u / 2 + 10u) << "the budget did not hold back the flood inside TLS";
  EXPECT_GE(guard->throttled(), 1u);
  ::close(client);
}

// A file that cannot serve is named with its setting.
TEST(TlsServerContext, AnUnusableFileIsNamedWithItsSetting) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("guard_tls_files_" + std::to_string(::getpid()));
  testing::TestPki pki(dir, "clinic");
  const testing::PemFiles server = pki.Issue("localhost", true);
  const testing::PemFiles other = pki.Issue("other", true);
  ASSERT_TRUE(pki.ok());
  const auto refusal = [](const TlsFiles& files) {
    try {
      TlsServerContext::Create(files);
    } catch (const TlsFileError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal({pki.ca(), server.certificate, other.key}).find("tls_key"), std::string::npos)
      << "a key that is not the certificate's";
  EXPECT_NE(refusal({server.key, server.certificate, server.key}).find("tls_ca"), std::string::npos)
      << "a CA file holding a key";
  EXPECT_NE(refusal({pki.ca(), (dir / "none.pem").string(), server.key}).find("tls_certificate"),
            std::string::npos);
  EXPECT_EQ(refusal({pki.ca(), server.certificate, server.key}), "accepted");
}

}  // namespace
}  // namespace bsls::rpc
