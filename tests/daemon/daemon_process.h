// Starts the real bslsd executable for the integration tests: a temporary
// directory holds its configuration, store and Unix socket; the tests talk
// to it over gRPC like any client and stop it with signals.
#ifndef BSLS_TESTS_DAEMON_DAEMON_PROCESS_H_
#define BSLS_TESTS_DAEMON_DAEMON_PROCESS_H_

#include <arpa/inet.h>
#include <fcntl.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "bsls/testing/build_paths.h"
#include "bsls/testing/spawn.h"
#include "bsls/v1/capture.grpc.pb.h"

namespace bsls::testing {

namespace fs = std::filesystem;

// Removes the daemon directories made during a test once the test has
// passed (stores, logs, keys); a failed test's are kept for its log.
class DaemonDirCleaner : public ::testing::EmptyTestEventListener {
 public:
  // The one cleaner of this test process, appended to GoogleTest's listeners.
  static DaemonDirCleaner& Instance() {
    static DaemonDirCleaner* cleaner = [] {
      auto* made = new DaemonDirCleaner;  // owned by GoogleTest's listener list
      ::testing::UnitTest::GetInstance()->listeners().Append(made);
      return made;
    }();
    return *cleaner;
  }

  // `dir` goes when the test running now ends well.
  void Add(const fs::path& dir) { dirs_.push_back(dir); }

  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (info.result() != nullptr && info.result()->Passed()) {
      std::error_code ec;
      for (const fs::path& dir : dirs_) fs::remove_all(dir, ec);
    }
    dirs_.clear();
  }

 private:
  std::vector<fs::path> dirs_;
};

// A fresh directory under the test temp dir, world-searchable so that
// callers of other uids reach the socket inside; removed after the test
// when it passes.
inline fs::path MakeDaemonDir(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("bslsd_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  ::chmod(dir.c_str(), 0755);
  DaemonDirCleaner::Instance().Add(dir);
  return dir;
}

// The group of the test daemons' sockets when the tests run as root: the
// probes of other uids get it as a supplementary group (a socket is never
// world-writable, bslsd refuses that).
constexpr gid_t kTestSocketGroup = 60000;

// The configuration file of a test daemon: simulated devices unless
// `extra` says otherwise (YAML appended verbatim, top-level keys). The
// daemon keeps the test's own uid and gid (`user:`; as root it would
// otherwise become `bsls`), its socket is mode 0660 and, as root, of group
// kTestSocketGroup.
inline fs::path WriteDaemonConfig(const fs::path& dir, const std::string& extra = {}) {
  const fs::path path = dir / "bslsd.yaml";
  std::ofstream out(path);
  out << "store:\n  root: " << (dir / "store").string() << "\n  reserve_mib: 16\n"
      << "listen:\n  unix_socket: " << (dir / "bslsd.sock").string()
      << "\n  socket_mode: \"0660\"\n"
      << (::geteuid() == 0 ? "  socket_group: \"" + std::to_string(kTestSocketGroup) + "\"\n"
                           : std::string())
      << "user: \"" << ::geteuid() << ":" << ::getegid() << "\"\n"
      << "log_level: warn\n"
      // A still head: one rendered view per camera and slide (rendering is
      // the simulated framestore's only slow step).
      << "framestore:\n  simulated_breathing_mm: 0\n"
      << extra;
  return path;
}

class DaemonProcess : public ChildProcess {
 public:
  // Starts bslsd with `config` and extra arguments; stdout and stderr go to
  // <dir>/bslsd.log. Returns once the socket answers GetStatus (or after
  // `timeout`, with ready() false).
  DaemonProcess(const fs::path& dir, const fs::path& config, std::vector<std::string> args = {},
                std::chrono::seconds timeout = std::chrono::seconds(120))
      : dir_(dir), socket_(dir / "bslsd.sock") {
    std::vector<std::string> argv = {bsls::testing::BslsdPath(), "--config", config.string()};
    argv.insert(argv.end(), args.begin(), args.end());
    Spawn(std::move(argv), (dir / "bslsd.log").string());
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until && !exited()) {
      if (fs::exists(socket_)) {
        auto stub = Stub();
        grpc::ClientContext context;
        context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(2));
        v1::DeviceStatus status;
        if (stub->GetStatus(&context, {}, &status).ok()) {
          ready_ = true;
          break;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ~DaemonProcess() {
    if (pid() > 0 && !exited()) Kill();
  }

  bool ready() const { return ready_; }
  const fs::path& socket() const { return socket_; }
  // The daemon's log so far (for failure messages).
  std::string Log() const {
    std::ifstream in(dir_ / "bslsd.log");
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  // A new channel to the daemon's socket.
  std::shared_ptr<grpc::Channel> Channel() const { return Channel(grpc::ChannelArguments()); }
  // A new channel to the daemon's socket with `args` (transport settings of
  // a particular client).
  std::shared_ptr<grpc::Channel> Channel(const grpc::ChannelArguments& args) const {
    return grpc::CreateCustomChannel("unix:" + socket_.string(), grpc::InsecureChannelCredentials(),
                                     args);
  }
  std::unique_ptr<v1::CaptureDaemon::Stub> Stub() const {
    return v1::CaptureDaemon::NewStub(Channel());
  }
  // A stub on a connection of its own with `args`.
  std::unique_ptr<v1::CaptureDaemon::Stub> Stub(grpc::ChannelArguments args) const {
    args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
    return v1::CaptureDaemon::NewStub(Channel(args));
  }

  // SIGTERM, then waits up to `timeout`: the exit status (-1 if it did not exit).
  int Terminate(std::chrono::seconds timeout = std::chrono::seconds(60)) {
    ::kill(pid(), SIGTERM);
    return Wait(timeout);
  }

 private:
  fs::path dir_;
  fs::path socket_;
  bool ready_ = false;
};

// A client context with a deadline (our clients always set one).
inline std::unique_ptr<grpc::ClientContext> Deadline(std::chrono::milliseconds ms) {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + ms);
  return context;
}

// A TCP port on loopback that nothing listens on right now (0 if none
// could be had).
inline int FreeLoopbackPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0)
    port = ntohs(address.sin_port);
  ::close(fd);
  return port;
}

}  // namespace bsls::testing

#endif  // BSLS_TESTS_DAEMON_DAEMON_PROCESS_H_
