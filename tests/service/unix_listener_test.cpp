// UnixListener under hostile callers. Out of descriptors, the
// accept loop sheds the waiting callers at once and does not spin (the
// listener runs in a child process whose descriptor limit is set just above
// what it holds, so that each further connection meets EMFILE). Beyond the
// connection limits, per user and in total, connections are closed at once.
// A Create that fails after binding leaves no socket file.
#include "bsls/service/unix_listener.h"

#include <fcntl.h>
#include <grp.h>
#include <grpcpp/create_channel.h>
#include <grpcpp/server.h>
#include <grpcpp/server_builder.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bsls/testing/raw_connections.h"
#include "bsls/v1/capture.grpc.pb.h"

namespace bsls::service {
namespace {

// User + system CPU seconds of process `pid` (from /proc/<pid>/stat).
double CpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream fields(text.substr(text.rfind(')') + 2));
  std::string field;
  long ticks = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i)
    if (i == 14 || i == 15) ticks += std::stol(field);  // utime, stime
  return static_cast<double>(ticks) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

// Descriptors open in this process.
int OpenDescriptors() {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/fd"))
    ++n;
  return n;
}

TEST(UnixListener, OutOfDescriptorsItShedsCallersAndDoesNotSpin) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("bsls_listener_" + std::to_string(::getpid()) + ".sock"))
                               .string();
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(ready[0]);
    v1::CaptureDaemon::Service unimplemented;  // a server needs one service
    grpc::ServerBuilder builder;
    builder.RegisterService(&unimplemented);
    std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
    auto listener = UnixListener::Create({path, 0600});
    if (!server) ::_exit(2);
    if (!listener.ok()) ::_exit(5);
    PeerRegistry registry;
    RolePolicy policy;
    (*listener)->Start(server.get(), &registry, &policy);
    // Room for a few connections more, then EMFILE.
    const rlim_t limit = static_cast<rlim_t>(OpenDescriptors() + 4);
    const rlimit low{limit, limit};
    if (::setrlimit(RLIMIT_NOFILE, &low) != 0) ::_exit(3);
    const char byte = 1;
    if (::write(ready[1], &byte, 1) != 1) ::_exit(4);
    for (;;) ::pause();
  }
  ::close(ready[1]);
  char byte = 0;
  if (::read(ready[0], &byte, 1) != 1) {
    int status = 0;
    ::waitpid(child, &status, 0);
    FAIL() << "the listener did not start: exit " << WEXITSTATUS(status);
  }
  ::close(ready[0]);

  // Far more callers than the child has descriptors for.
  std::vector<int> clients;
  for (int i = 0; i < 40; ++i) {
    const int fd = testing::ConnectUnixAs(0, path);
    if (fd >= 0) clients.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double cpu_before = CpuSeconds(child);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const double cpu_used = CpuSeconds(child) - cpu_before;
  // Shed callers see their connection closed (end of file or a reset).
  int closed = 0;
  for (int fd : clients) {
    timeval wait{0, 200000};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
    char buffer[64];
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n == 0 || (n < 0 && errno == ECONNRESET)) ++closed;
    ::close(fd);
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  std::filesystem::remove(path);
  ASSERT_GE(clients.size(), 30u);
  // Spinning on EMFILE used a whole core (4.85 s of CPU in 5 s).
  EXPECT_LT(cpu_used, 0.5) << "the accept loop spins";
  EXPECT_GE(closed, 20) << "callers beyond the descriptor limit were not shed";
}

// A Create that fails after the socket is bound (here rpc::UnixAcceptor's
// pipe2, out of descriptors) removes the socket file it made: a daemon that
// failed to start leaves no file for callers to find. Run in a child
// process whose descriptor limit leaves exactly one descriptor free: the
// socket takes it, the wake pipe finds none.
TEST(UnixListener, AFailedCreateLeavesNoSocketFile) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("bsls_listener_pipe_" + std::to_string(::getpid()) + ".sock"))
                               .string();
  std::filesystem::remove(path);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const rlim_t limit = static_cast<rlim_t>(OpenDescriptors() + 16);
    const rlimit low{limit, limit};
    if (::setrlimit(RLIMIT_NOFILE, &low) != 0) ::_exit(2);
    std::vector<int> filler;
    for (int fd; (fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC)) >= 0;) filler.push_back(fd);
    if (errno != EMFILE || filler.empty()) ::_exit(3);
    ::close(filler.back());  // the one descriptor free
    auto listener = UnixListener::Create({path, 0600});
    if (listener.ok()) ::_exit(4);
    if (listener.status().code() != ErrorCode::kUnavailable ||
        listener.status().message().find("pipe") == std::string::npos)
      ::_exit(5);
    ::_exit(std::filesystem::exists(path) ? 6 : 0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  const bool left_behind = std::filesystem::exists(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_NE(WEXITSTATUS(status), 4) << "Create succeeded with one descriptor free";
  EXPECT_NE(WEXITSTATUS(status), 5) << "Create failed, but not at pipe2";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "exit " << WEXITSTATUS(status);
  EXPECT_FALSE(left_behind) << "the failed Create left its socket file " << path;
}

// One daemon per socket: a second listener on a live socket is refused and
// leaves it working; once the first is gone, its stale file is replaced.
TEST(UnixListener, ASecondListenerOnALiveSocketIsRefused) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("bsls_listener_twice_" + std::to_string(::getpid()) + ".sock"))
                               .string();
  std::filesystem::remove(path);
  auto first = UnixListener::Create({path, 0600});
  ASSERT_TRUE(first.ok()) << first.status().message();
  auto second = UnixListener::Create({path, 0600});
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), ErrorCode::kAlreadyExists);
  const int client = testing::ConnectUnixAs(0, path);
  EXPECT_GE(client, 0) << "the first listener's socket was taken";
  if (client >= 0) ::close(client);
  first->reset();  // closed without Start/Stop: the file stays, stale
  ASSERT_TRUE(std::filesystem::exists(path));
  auto third = UnixListener::Create({path, 0600});
  EXPECT_TRUE(third.ok()) << third.status().message();
  third->reset();
  std::filesystem::remove(path);
}

// The limits on connections open at once: one user beyond its
// share and everybody beyond the total are closed at once, while others are
// still served. The listener runs in a child process (gRPC is not used in
// this one before it forks the caller of another uid).
TEST(UnixListener, ConnectionsBeyondTheUsersShareOrTheTotalAreClosedAtOnce) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to connect as other uids";
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("bsls_listener_limits_" + std::to_string(::getpid()) + ".sock"))
                               .string();
  std::filesystem::remove(path);
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t server_child = ::fork();
  ASSERT_GE(server_child, 0);
  if (server_child == 0) {
    ::close(ready[0]);
    v1::CaptureDaemon::Service unimplemented;  // answers UNIMPLEMENTED: an answer
    grpc::ServerBuilder builder;
    builder.RegisterService(&unimplemented);
    std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
    UnixListenerOptions options;
    options.path = path;
    options.mode = 0666;
    options.connections.max_connections = 6;
    options.connections.max_connections_per_user = 3;
    auto listener = UnixListener::Create(options);
    if (!server || !listener.ok()) ::_exit(2);
    PeerRegistry registry;
    RolePolicy policy;
    (*listener)->Start(server.get(), &registry, &policy);
    const char byte = 1;
    if (::write(ready[1], &byte, 1) != 1) ::_exit(4);
    for (;;) ::pause();
  }
  ::close(ready[1]);
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1) << "the listener did not start";
  ::close(ready[0]);
  std::vector<int> open;
  auto stop = [&] {
    for (int fd : open) ::close(fd);
    ::kill(server_child, SIGKILL);
    int status = 0;
    ::waitpid(server_child, &status, 0);
    std::filesystem::remove(path);
  };

  // Root takes its share: three stay open, the fourth and fifth are closed.
  for (int i = 0; i < 3; ++i) open.push_back(testing::ConnectUnixAs(0, path));
  for (int fd : open)
    EXPECT_FALSE(testing::ClosedWithin(fd, 300)) << "a connection within the share";
  for (int i = 0; i < 2; ++i) {
    const int extra = testing::ConnectUnixAs(0, path);
    EXPECT_TRUE(testing::ClosedWithin(extra, 2000))
        << "a connection beyond root's share stayed open";
    ::close(extra);
  }

  // Another user is still served meanwhile.
  const pid_t caller = ::fork();
  ASSERT_GE(caller, 0);
  if (caller == 0) {
    if (::setgroups(0, nullptr) != 0 || ::setgid(60001) != 0 || ::setuid(60001) != 0) ::_exit(3);
    auto stub = v1::CaptureDaemon::NewStub(
        grpc::CreateChannel("unix:" + path, grpc::InsecureChannelCredentials()));
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::DeviceStatus reply;
    const grpc::Status status = stub->GetStatus(&context, {}, &reply);
    ::_exit(status.error_code() == grpc::StatusCode::UNIMPLEMENTED ? 0 : 10 + status.error_code());
  }
  int status = 0;
  ::waitpid(caller, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << "uid 60001 was not answered while root held its share (exit " << WEXITSTATUS(status)
      << ")";
  // Its connection goes with it.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  // The total: root's three and uid 60002's three fill it; uid 60003 is refused.
  for (int i = 0; i < 3; ++i) {
    open.push_back(testing::ConnectUnixAs(60002, path));
    EXPECT_FALSE(testing::ClosedWithin(open.back(), 300)) << "uid 60002's connection " << i;
  }
  const int beyond = testing::ConnectUnixAs(60003, path);
  EXPECT_TRUE(testing::ClosedWithin(beyond, 2000)) << "a connection beyond the total stayed open";
  ::close(beyond);
  stop();
}

}  // namespace
}  // namespace bsls::service
