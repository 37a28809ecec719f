// rpc::TcpAcceptor's binding: every address the host resolves to, on one
// port; an address that cannot be bound is skipped while another can, and
// the listener is refused naming each address and reason when none can; a
// plain-TCP listener refuses a name that resolves to a network address.
// The limits and the EMFILE back-off (the accept loop it shares with
// rpc::UnixAcceptor) are tested through the services: processd_server_test,
// unix_listener_test.
#include "bsls/rpc/tcp_acceptor.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <string>
#include <thread>

namespace bsls::rpc {
namespace {

// A connection to `host` (numeric, IPv4 or IPv6) at `port`, or -1.
int Connect(const std::string& host, int port) {
  sockaddr_storage to{};
  socklen_t length = 0;
  auto* v4 = reinterpret_cast<sockaddr_in*>(&to);
  auto* v6 = reinterpret_cast<sockaddr_in6*>(&to);
  if (::inet_pton(AF_INET, host.c_str(), &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    v4->sin_port = htons(static_cast<std::uint16_t>(port));
    length = sizeof(sockaddr_in);
  } else if (::inet_pton(AF_INET6, host.c_str(), &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons(static_cast<std::uint16_t>(port));
    length = sizeof(sockaddr_in6);
  } else {
    return -1;
  }
  const int fd = ::socket(to.ss_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&to), length) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Whether this machine has the IPv6 loopback address (::1 can be bound).
bool HasIpv6Loopback() {
  const int fd = ::socket(AF_INET6, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_in6 address{};
  address.sin6_family = AF_INET6;
  address.sin6_addr = in6addr_loopback;
  const bool ok = ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  ::close(fd);
  return ok;
}

// The wildcard (":0") resolves to 0.0.0.0 and ::; both are bound on one
// port, and a connection to 127.0.0.1 and one to ::1 both come through,
// each with the descriptor of a different listening socket.
TEST(TcpAcceptor, BindsEveryAddressTheHostResolvesToOnOnePort) {
  if (!HasIpv6Loopback()) GTEST_SKIP() << "no IPv6 loopback on this machine";
  TcpAcceptorOptions options;
  options.address = ":0";
  std::string error;
  std::unique_ptr<TcpAcceptor> acceptor = TcpAcceptor::Create(options, &error);
  ASSERT_NE(acceptor, nullptr) << error;
  const std::string port = std::to_string(acceptor->port());
  ASSERT_NE(acceptor->port(), 0);
  std::vector<std::string> bound = acceptor->bound();
  std::sort(bound.begin(), bound.end());
  EXPECT_EQ(bound, (std::vector<std::string>{"0.0.0.0:" + port, "[::]:" + port}));

  std::mutex mutex;
  std::set<int> listeners;
  std::atomic<int> handed{0};
  acceptor->Start([&](int fd, int listener_fd) {
    std::lock_guard lock(mutex);
    listeners.insert(listener_fd);
    ::close(fd);
    ++handed;
    return true;
  });
  const int v4 = Connect("127.0.0.1", acceptor->port());
  const int v6 = Connect("::1", acceptor->port());
  EXPECT_GE(v4, 0) << "127.0.0.1:" << port;
  EXPECT_GE(v6, 0) << "[::1]:" << port;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (handed < 2 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  acceptor->Stop();
  for (const int fd : {v4, v6})
    if (fd >= 0) ::close(fd);
  EXPECT_EQ(handed, 2);
  EXPECT_EQ(acceptor->accepted(), 2u);
  EXPECT_EQ(listeners.size(), 2u) << "both connections came through one listening socket";
}

// A numeric address resolves to itself alone: one socket.
TEST(TcpAcceptor, ANumericAddressIsBoundAlone) {
  TcpAcceptorOptions options;
  options.address = "127.0.0.1:0";
  std::string error;
  std::unique_ptr<TcpAcceptor> acceptor = TcpAcceptor::Create(options, &error);
  ASSERT_NE(acceptor, nullptr) << error;
  EXPECT_EQ(acceptor->bound(),
            (std::vector<std::string>{"127.0.0.1:" + std::to_string(acceptor->port())}));
}

// When no address can be bound (here the port is taken), the listener is
// refused with the address given and each resolved address with its reason.
TEST(TcpAcceptor, NoAddressBoundIsAnErrorNamingEachAndWhy) {
  TcpAcceptorOptions options;
  options.address = "127.0.0.1:0";
  std::string error;
  std::unique_ptr<TcpAcceptor> first = TcpAcceptor::Create(options, &error);
  ASSERT_NE(first, nullptr) << error;
  const std::string taken = "127.0.0.1:" + std::to_string(first->port());
  options.address = taken;
  EXPECT_EQ(TcpAcceptor::Create(options, &error), nullptr);
  EXPECT_NE(error.find("TCP address '" + taken + "'"), std::string::npos) << error;
  EXPECT_NE(error.find(taken + ": bind/listen: "), std::string::npos) << error;
  EXPECT_NE(error.find(std::strerror(EADDRINUSE)), std::string::npos) << error;
}

// An address that cannot be bound is skipped while another of the name's
// can: the wildcard's IPv4 half is taken on this port, its IPv6 half is
// still served.
TEST(TcpAcceptor, AnAddressThatCannotBeBoundIsSkippedWhileAnotherIs) {
  if (!HasIpv6Loopback()) GTEST_SKIP() << "no IPv6 loopback on this machine";
  TcpAcceptorOptions options;
  options.address = "0.0.0.0:0";
  std::string error;
  std::unique_ptr<TcpAcceptor> first = TcpAcceptor::Create(options, &error);
  ASSERT_NE(first, nullptr) << error;
  const std::string port = std::to_string(first->port());
  options.address = ":" + port;
  std::unique_ptr<TcpAcceptor> second = TcpAcceptor::Create(options, &error);
  ASSERT_NE(second, nullptr) << error;
  EXPECT_EQ(second->bound(), (std::vector<std::string>{"[::]:" + port}));
}

// Plain TCP is for loopback: a name that resolves to any other address
// (here the wildcard, 0.0.0.0 and ::) is refused, naming that address.
TEST(TcpAcceptor, LoopbackOnlyRefusesANameResolvingToANetworkAddress) {
  TcpAcceptorOptions options;
  options.address = ":0";
  options.loopback_only = true;
  std::string error;
  EXPECT_EQ(TcpAcceptor::Create(options, &error), nullptr);
  EXPECT_NE(error.find("TCP address ':0'"), std::string::npos) << error;
  EXPECT_NE(error.find("which is not a loopback address"), std::string::npos) << error;
  options.address = "127.0.0.1:0";
  EXPECT_NE(TcpAcceptor::Create(options, &error), nullptr) << error;
}

}  // namespace
}  // namespace bsls::rpc
