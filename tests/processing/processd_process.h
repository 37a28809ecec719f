// bsls-processd replicas as real processes, for the tests and the benchmark
// that need more than the in-process server: each replica is the installed
// executable on plain loopback TCP (port 0, read back from its `tcp_port=N`
// line), killed or stopped with signals. Also the /proc figures the
// robustness test watches (open descriptors, resident memory, CPU time).
// No GoogleTest here: the benchmark includes it too.
#ifndef BSLS_TESTS_PROCESSING_PROCESSD_PROCESS_H_
#define BSLS_TESTS_PROCESSING_PROCESSD_PROCESS_H_

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bsls/testing/spawn.h"

namespace bsls::processing::test {

namespace fs = std::filesystem;

// A fresh private folder under $TMPDIR (or /tmp) named after `prefix`.
inline fs::path MakeTempFolder(const std::string& prefix) {
  const char* base = std::getenv("TMPDIR");
  std::string pattern = std::string(base && *base ? base : "/tmp") + "/" + prefix + "XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr)
    throw std::runtime_error("cannot create a folder like " + pattern);
  return pattern;
}

// The whole text of a file ("" when it cannot be read).
inline std::string ReadWholeFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Open file descriptors of process `pid` (entries of /proc/PID/fd), -1 if gone.
inline int OpenDescriptors(pid_t pid) {
  std::error_code ec;
  int n = 0;
  for (fs::directory_iterator it("/proc/" + std::to_string(pid) + "/fd", ec), end; !ec && it != end;
       it.increment(ec))
    ++n;
  return ec ? -1 : n;
}

// Resident memory of process `pid` (VmRSS of /proc/PID/status), KiB; -1 if gone.
inline long ResidentKib(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  return -1;
}

// User + system CPU time of process `pid` so far, seconds (all its threads);
// -1 if gone.
inline double CpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::size_t close = text.rfind(')');  // the command name may hold spaces
  if (close == std::string::npos) return -1;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; fields >> field; ++i) {  // field 3 is the state
    if (i == 14) utime = std::stoull(field);
    if (i == 15) {
      stime = std::stoull(field);
      break;
    }
  }
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

// One bsls-processd replica: `--socket "" --tcp 127.0.0.1:0` with plain
// loopback TCP (and a Unix socket too when `socket` is given), `--workers`,
// `--replica`, plus `extra` arguments. Its stdout
// and stderr go to <folder>/<replica>.log (a file, never a pipe that could
// fill up and stall the replica).
class ProcessdProcess : public bsls::testing::ChildProcess {
 public:
  // Starts the replica and returns once it printed its port (ready() true) or
  // after `timeout` / its early exit (ready() false; Log() says why).
  // `tcp` is where it listens ("127.0.0.1:0": a port of the system's choice).
  ProcessdProcess(const std::string& binary, const fs::path& folder, const std::string& replica,
                  int workers, const std::vector<std::string>& extra = {},
                  std::chrono::seconds timeout = std::chrono::seconds(120),
                  const std::string& tcp = "127.0.0.1:0", const std::string& socket = "")
      : name_(replica), log_(folder / (replica + ".log")) {
    std::vector<std::string> argv = {binary,
                                     "--socket",
                                     socket,
                                     "--tcp",
                                     tcp,
                                     "--workers",
                                     std::to_string(workers),
                                     "--replica",
                                     replica,
                                     "--set",
                                     "listen.plaintext_loopback=true"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    Spawn(std::move(argv), log_.string(), /*truncate=*/true);
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until && !exited()) {
      const std::string text = Log();
      if (const std::size_t at = text.find("tcp_port=");
          at != std::string::npos && text.find('\n', at) != std::string::npos) {
        port_ = std::atoi(text.c_str() + at + 9);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  // Kills the replica if it still runs.
  ~ProcessdProcess() {
    if (pid() > 0 && !exited()) Kill();
  }
  ProcessdProcess(const ProcessdProcess&) = delete;
  ProcessdProcess& operator=(const ProcessdProcess&) = delete;

  // True once the replica serves (its port is known).
  bool ready() const { return port_ > 0; }
  // The TCP port it serves (0 until ready).
  int port() const { return port_; }
  // The replica name it puts in its Results.
  const std::string& name() const { return name_; }
  // "127.0.0.1:PORT", for a target list.
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  // What the replica wrote so far.
  std::string Log() const { return ReadWholeFile(log_); }

  // SIGTERM (drain), then waits: the exit code, or -1 if it did not exit in
  // time or died of a signal (then it is killed).
  int Terminate(std::chrono::seconds timeout = std::chrono::seconds(60)) {
    if (!exited()) ::kill(pid(), SIGTERM);
    const int code = Wait(timeout);
    if (!exited()) Kill();
    return code;
  }

 private:
  std::string name_;
  fs::path log_;
  int port_ = 0;
};

// "ipv4:127.0.0.1:p1,127.0.0.1:p2,..." for round_robin over `replicas`.
inline std::string RoundRobinTarget(const std::vector<std::unique_ptr<ProcessdProcess>>& replicas) {
  std::string target = "ipv4:";
  for (std::size_t i = 0; i < replicas.size(); ++i)
    target += (i ? "," : "") + replicas[i]->address();
  return target;
}

}  // namespace bsls::processing::test

#endif  // BSLS_TESTS_PROCESSING_PROCESSD_PROCESS_H_
