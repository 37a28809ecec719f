// bsls-processd's server assembly: the Unix socket and plain loopback TCP
// for one machine, mutual TLS for the network (every handshake without a
// certificate of the configured CA fails), draining.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "bsls/contract/frame_message.h"
#include "bsls/processing/processing_client.h"
#include "bsls/testing/certificates.h"
#include "bsls/testing/hostile_frame.h"
#include "bsls/testing/raw_connections.h"
#include "raw_calls.h"
#include "server.h"

namespace bsls::processd {
namespace {

namespace fs = std::filesystem;

// Bytes that are no message of any type: field 1, length-delimited, with a
// length of 4 GiB that does not follow.

class ProcessdServer : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("processd-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static grpc::Status Info(const std::shared_ptr<grpc::Channel>& channel, v1::ServerInfo* info) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
    return v1::Processing::NewStub(channel)->GetServerInfo(&context, {}, info);
  }

  // A configuration serving mutual TLS alone, on 127.0.0.1 at a free port,
  // with `server` as its certificate and `pki`'s CA for its clients.
  static Config TlsOnLoopback(const testing::PemFiles& server, const testing::TestPki& pki) {
    Config config;
    config.listen.unix_socket = "";
    config.listen.tcp = "127.0.0.1:0";
    config.listen.tls_certificate = server.certificate;
    config.listen.tls_key = server.key;
    config.listen.tls_client_ca = pki.ca();
    return config;
  }

  // Info asked every 100 ms until it answers OK or 20 tries have failed;
  // the last status.
  static grpc::Status InfoWithin2Seconds(const std::shared_ptr<grpc::Channel>& channel) {
    v1::ServerInfo info;
    grpc::Status status;
    for (int attempt = 0; attempt < 20 && !(status = Info(channel, &info)).ok(); ++attempt)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return status;
  }

  fs::path dir_;
};

TEST_F(ProcessdServer, ServesTheUnixSocketAndPlainLoopback) {
  Config config;
  config.listen.unix_socket = (dir_ / "processd.sock").string();
  config.listen.tcp = "127.0.0.1:0";
  config.listen.plaintext_loopback = true;
  config.workers = 1;
  config.replica = "r1";
  auto server = Server::Start(config, "test");
  ASSERT_GT(server->tcp_port(), 0);
  for (const std::string& target :
       {"unix:" + config.listen.unix_socket, "127.0.0.1:" + std::to_string(server->tcp_port())}) {
    processing::ClientOptions options;
    options.target = target;
    v1::ServerInfo info;
    const grpc::Status status = Info(processing::OpenProcessingChannel(options), &info);
    ASSERT_TRUE(status.ok()) << target << ": " << status.error_message();
    EXPECT_EQ(info.replica(), "r1");
    EXPECT_EQ(info.workers(), 1u);
    EXPECT_EQ(info.queue(), 2u);
  }
  server->Drain();
  EXPECT_FALSE(fs::exists(config.listen.unix_socket));
}

// Draining stops work under way inside its stages: two calls
// decoding frames that keep every stage busy end (UNAVAILABLE) and the
// drain returns well before their decodes would have ended.
TEST_F(ProcessdServer, DrainStopsWorkInsideItsStages) {
  Config config;
  config.listen.unix_socket = (dir_ / "processd.sock").string();
  config.workers = 2;
  auto server = Server::Start(config, "test");
  processing::ClientOptions options;
  options.target = "unix:" + config.listen.unix_socket;
  options.timeout = std::chrono::minutes(5);
  v1::ProcessFrameRequest request;
  contract::ToFrameMessage(testing::HostileFrame(), request.mutable_frame());
  request.set_side(v1::SIDE_LEFT);
  auto start = std::chrono::steady_clock::now();
  {
    processing::ProcessingClient client(processing::OpenProcessingChannel(options), options);
    (void)client.ProcessFrame(request);
  }
  const auto whole = std::chrono::steady_clock::now() - start;

  std::vector<grpc::Status> statuses(2);
  std::vector<std::thread> callers;
  for (grpc::Status& status : statuses)
    callers.emplace_back([&] {
      processing::ProcessingClient client(processing::OpenProcessingChannel(options), options);
      status = client.ProcessFrame(request).status;
    });
  while (server->service().Stats().busy < 2 &&
         std::chrono::steady_clock::now() - start < whole * 10)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_EQ(server->service().Stats().busy, 2);
  start = std::chrono::steady_clock::now();
  server->Drain();
  const auto drained = std::chrono::steady_clock::now() - start;
  for (std::thread& t : callers) t.join();
  for (const grpc::Status& status : statuses)
    EXPECT_FALSE(status.ok()) << "a call went on to its end while the service drained";
  EXPECT_EQ(server->service().Stats().busy, 0);
  EXPECT_LT(drained, whole / 2) << "decode " << std::chrono::duration<double>(whole).count()
                                << " s, drain " << std::chrono::duration<double>(drained).count()
                                << " s";
}

// The HTTP/2 limits reach the server: a connection without calls
// is closed after listen.max_connection_idle_ms and the client reconnects.
TEST_F(ProcessdServer, AConnectionWithoutCallsIsClosedAfterTheIdleLimit) {
  Config config;
  config.listen.unix_socket = (dir_ / "processd.sock").string();
  config.listen.http2.max_connection_idle_ms = 500;
  config.workers = 1;
  auto server = Server::Start(config, "test");
  std::shared_ptr<grpc::Channel> channel =
      grpc::CreateChannel("unix:" + config.listen.unix_socket, grpc::InsecureChannelCredentials());
  v1::ServerInfo info;
  ASSERT_TRUE(Info(channel, &info).ok());
  ASSERT_EQ(channel->GetState(false), GRPC_CHANNEL_READY);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (channel->GetState(false) == GRPC_CHANNEL_READY && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_NE(channel->GetState(false), GRPC_CHANNEL_READY) << "the idle connection stayed open";
  EXPECT_TRUE(Info(channel, &info).ok());
  server->Drain();
}

// Bytes that are not the request message get INVALID_ARGUMENT naming the
// message type, on every method that takes one request (gRPC alone gives
// INTERNAL with an empty message); the service still answers after.
// (In a request stream a malformed message reads as the stream's end.)
TEST_F(ProcessdServer, AMalformedRequestIsInvalidArgumentWithAMessage) {
  Config config;
  config.listen.unix_socket = (dir_ / "processd.sock").string();
  config.workers = 1;
  auto server = Server::Start(config, "test");
  std::shared_ptr<grpc::Channel> channel =
      grpc::CreateChannel("unix:" + config.listen.unix_socket, grpc::InsecureChannelCredentials());
  grpc::GenericStub stub(channel);
  const google::protobuf::ServiceDescriptor* service =
      google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(
          v1::Processing::service_full_name());
  ASSERT_NE(service, nullptr);
  const int tried = processing::test::ExpectMalformedRequestsRefused(stub, *service);
  EXPECT_GE(tried, 6);
  v1::ServerInfo info;
  EXPECT_TRUE(Info(channel, &info).ok());
  server->Drain();
}

// The Unix socket's connections are limited per user and in all
// (listen.max_connections*); connections beyond are closed at once while
// other users are still let in, and the service answers after.
TEST_F(ProcessdServer, UnixConnectionsBeyondTheLimitsAreClosedAtOnce) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to connect as other uids";
  Config config;
  config.listen.unix_socket = (dir_ / "processd.sock").string();
  config.listen.connections.max_connections = 4;
  config.listen.connections.max_connections_per_user = 2;
  config.workers = 1;
  auto server = Server::Start(config, "test");
  // Other uids reach the socket: the folder is searchable, the socket 0660 of root's group.
  ::chmod(dir_.c_str(), 0755);
  ::chmod(config.listen.unix_socket.c_str(), 0666);
  std::vector<int> open;
  for (int i = 0; i < 2; ++i) open.push_back(testing::ConnectUnixAs(0, config.listen.unix_socket));
  for (int fd : open)
    EXPECT_FALSE(testing::ClosedWithin(fd, 300)) << "a connection within root's share";
  const int beyond_share = testing::ConnectUnixAs(0, config.listen.unix_socket);
  EXPECT_TRUE(testing::ClosedWithin(beyond_share, 2000)) << "root's third connection stayed open";
  ::close(beyond_share);
  for (uid_t uid : {60001u, 60002u}) {
    open.push_back(testing::ConnectUnixAs(uid, config.listen.unix_socket));
    EXPECT_FALSE(testing::ClosedWithin(open.back(), 300)) << "uid " << uid << " was not let in";
  }
  const int beyond_total = testing::ConnectUnixAs(60003, config.listen.unix_socket);
  EXPECT_TRUE(testing::ClosedWithin(beyond_total, 2000))
      << "a connection beyond the total stayed open";
  ::close(beyond_total);
  for (int fd : open) ::close(fd);
  // Once they are gone, the service answers again.
  std::shared_ptr<grpc::Channel> channel =
      grpc::CreateChannel("unix:" + config.listen.unix_socket, grpc::InsecureChannelCredentials());
  const grpc::Status status = InfoWithin2Seconds(channel);
  EXPECT_TRUE(status.ok()) << status.error_message();
  server->Drain();
  EXPECT_FALSE(fs::exists(config.listen.unix_socket));
}

// TCP connections are limited per peer address and in all
// (listen.max_tcp_connections*); connections beyond are closed at once while
// another address is still let in, and the service answers after.
TEST_F(ProcessdServer, TcpConnectionsBeyondTheLimitsAreClosedAtOnce) {
  Config config;
  config.listen.unix_socket = "";
  config.listen.tcp = "127.0.0.1:0";
  config.listen.plaintext_loopback = true;
  config.listen.connections.max_tcp_connections = 3;
  config.listen.connections.max_tcp_connections_per_peer = 2;
  config.workers = 1;
  auto server = Server::Start(config, "test");
  const int port = server->tcp_port();
  ASSERT_GT(port, 0);
  std::vector<int> open;
  for (int i = 0; i < 2; ++i) open.push_back(testing::ConnectTcpFrom("127.0.0.1", port));
  for (int fd : open) {
    ASSERT_GE(fd, 0);
    EXPECT_FALSE(testing::ClosedWithin(fd, 300)) << "a connection within the address's share";
  }
  const int beyond_share = testing::ConnectTcpFrom("127.0.0.1", port);
  EXPECT_TRUE(testing::ClosedWithin(beyond_share, 2000))
      << "the address's third connection stayed open";
  ::close(beyond_share);
  open.push_back(testing::ConnectTcpFrom("127.0.0.2", port));
  EXPECT_FALSE(testing::ClosedWithin(open.back(), 300)) << "another address was not let in";
  const int beyond_total = testing::ConnectTcpFrom("127.0.0.3", port);
  EXPECT_TRUE(testing::ClosedWithin(beyond_total, 2000))
      << "a connection beyond the total stayed open";
  ::close(beyond_total);
  for (int fd : open) ::close(fd);
  // Once they are gone, the service answers again.
  std::shared_ptr<grpc::Channel> channel =
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials());
  const grpc::Status status = InfoWithin2Seconds(channel);
  EXPECT_TRUE(status.ok()) << status.error_message();
  server->Drain();
}

// A peer that opens a TCP connection and never begins the TLS handshake
// holds its slot only until listen.handshake_timeout_ms: the server closes
// it, and a client of the same address is served after.
TEST_F(ProcessdServer, ATcpPeerThatNeverShakesHandsIsClosedAfterTheHandshakeTimeout) {
  testing::TestPki pki(dir_ / "pki", "clinic");
  const testing::PemFiles server_files = pki.Issue("localhost", true);
  const testing::PemFiles analyst = pki.Issue("analyst");
  ASSERT_TRUE(pki.ok());
  Config config = TlsOnLoopback(server_files, pki);
  config.listen.connections.max_tcp_connections_per_peer = 1;
  config.listen.http2.handshake_timeout_ms = 1000;
  auto server = Server::Start(config, "test");
  const int port = server->tcp_port();
  const int silent = testing::ConnectTcpFrom("127.0.0.1", port);
  ASSERT_GE(silent, 0);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(testing::ClosedWithin(silent, 500)) << "closed before the handshake timeout";
  EXPECT_TRUE(testing::ClosedWithin(silent, 4000)) << "a silent peer kept its connection";
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 4.0);
  ::close(silent);
  processing::ClientOptions good;
  good.target = "127.0.0.1:" + std::to_string(port);
  good.tls = {pki.ca(), analyst.certificate, analyst.key};
  v1::ServerInfo info;
  const grpc::Status ok = Info(processing::OpenProcessingChannel(good), &info);
  EXPECT_TRUE(ok.ok()) << ok.error_message();
  server->Drain();
}

// One instance per socket: a second server on a socket that a live one
// serves refuses to start and leaves it alone; a stale socket file (its
// server gone) is replaced; a server removes only the socket file it made.
TEST_F(ProcessdServer, OneLiveInstancePerSocket) {
  Config config;
  config.listen.unix_socket = (dir_ / "processd.sock").string();
  config.workers = 1;
  config.replica = "first";
  auto first = Server::Start(config, "test");
  Config second = config;
  second.replica = "second";
  try {
    Server::Start(second, "test");
    FAIL() << "a second instance started on a live socket";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("another live instance"), std::string::npos) << e.what();
  }
  processing::ClientOptions options;
  options.target = "unix:" + config.listen.unix_socket;
  v1::ServerInfo info;
  ASSERT_TRUE(Info(processing::OpenProcessingChannel(options), &info).ok());
  EXPECT_EQ(info.replica(), "first");
  // The first stops; a file at the path that is not its socket stays.
  fs::remove(config.listen.unix_socket);
  { std::ofstream(config.listen.unix_socket) << "not a socket"; }
  first->Drain();
  EXPECT_TRUE(fs::exists(config.listen.unix_socket));
  EXPECT_THROW(Server::Start(second, "test"), std::runtime_error);  // not a socket
  fs::remove(config.listen.unix_socket);
  // A stale socket file (nobody listens) is replaced.
  {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, config.listen.unix_socket.c_str(), sizeof(address.sun_path) - 1);
    ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
    ::close(fd);
  }
  auto third = Server::Start(second, "test");
  ASSERT_TRUE(Info(processing::OpenProcessingChannel(options), &info).ok());
  EXPECT_EQ(info.replica(), "second");
  third->Drain();
  EXPECT_FALSE(fs::exists(config.listen.unix_socket));
}

TEST_F(ProcessdServer, TcpServesOnlyMutualTlsClientsOfItsCa) {
  testing::TestPki pki(dir_ / "pki", "clinic");
  const testing::PemFiles server_files = pki.Issue("localhost", true);
  const testing::PemFiles analyst = pki.Issue("analyst");
  testing::TestPki rogue(dir_ / "pki", "rogue");
  const testing::PemFiles forged = rogue.Issue("analyst");
  ASSERT_TRUE(pki.ok() && rogue.ok());
  Config config = TlsOnLoopback(server_files, pki);
  auto server = Server::Start(config, "test");
  const std::string target = "127.0.0.1:" + std::to_string(server->tcp_port());

  processing::ClientOptions good;
  good.target = target;
  good.tls = {pki.ca(), analyst.certificate, analyst.key};
  v1::ServerInfo info;
  const grpc::Status ok = Info(processing::OpenProcessingChannel(good), &info);
  ASSERT_TRUE(ok.ok()) << ok.error_message();

  // 100 handshakes without a certificate and 100 with one of another CA:
  // every one fails, each on a fresh channel (no connection reuse).
  int plain_failures = 0, forged_failures = 0;
  for (int i = 0; i < 100; ++i) {
    grpc::ChannelArguments args;
    args.SetInt("bsls.test.fresh", i);  // a distinct channel, never a shared subchannel
    grpc::SslCredentialsOptions no_cert;
    no_cert.pem_root_certs = testing::ReadText(pki.ca());
    plain_failures +=
        !Info(grpc::CreateCustomChannel(target, grpc::SslCredentials(no_cert), args), &info).ok();
    processing::ClientOptions bad = good;
    bad.tls = {pki.ca(), forged.certificate, forged.key};
    grpc::SslCredentialsOptions forged_cert;
    forged_cert.pem_root_certs = testing::ReadText(pki.ca());
    forged_cert.pem_cert_chain = testing::ReadText(forged.certificate);
    forged_cert.pem_private_key = testing::ReadText(forged.key);
    forged_failures +=
        !Info(grpc::CreateCustomChannel(target, grpc::SslCredentials(forged_cert), args), &info)
             .ok();
  }
  EXPECT_EQ(plain_failures, 100);
  EXPECT_EQ(forged_failures, 100);
  // Plain TCP to a TLS port fails too; and the client refuses plain TCP to
  // another machine before it tries.
  EXPECT_FALSE(Info(grpc::CreateChannel(target, grpc::InsecureChannelCredentials()), &info).ok());
  processing::ClientOptions remote;
  remote.target = "processd.clinic:7000";
  EXPECT_THROW(processing::OpenProcessingChannel(remote), std::invalid_argument);
}

TEST_F(ProcessdServer, RefusesAnUnusableConfiguration) {
  Config config;
  config.listen.unix_socket = "";
  config.listen.tcp = "0.0.0.0:0";  // no TLS files
  EXPECT_THROW(Server::Start(config, "test"), ConfigError);
  config.listen.tls_certificate = (dir_ / "missing.pem").string();
  config.listen.tls_key = config.listen.tls_certificate;
  config.listen.tls_client_ca = config.listen.tls_certificate;
  EXPECT_THROW(Server::Start(config, "test"), rpc::TlsFileError);
}

}  // namespace
}  // namespace bsls::processd
