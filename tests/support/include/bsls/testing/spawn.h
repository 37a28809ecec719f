// Starting the product's executables from the tests: one fork/exec with the
// child's stdout and stderr in a log file, and the child's end (ChildProcess), shared by the
// launchers of bslsd (tests/daemon/daemon_process.h) and bsls-processd
// (tests/processing/processd_process.h).
#ifndef BSLS_TESTING_SPAWN_H_
#define BSLS_TESTING_SPAWN_H_

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace bsls::testing {

// Starts argv[0] with `argv`, its stdout and stderr appended to `log` (or
// written afresh with `truncate`); returns the child's pid (the child exits
// 127 when argv[0] cannot be run).
inline pid_t SpawnLogged(std::vector<std::string> argv, const std::string& log,
                         bool truncate = false) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | (truncate ? O_TRUNC : O_APPEND), 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> raw;
    for (std::string& a : argv) raw.push_back(a.data());
    raw.push_back(nullptr);
    ::execv(raw[0], raw.data());
    ::_exit(127);
  }
  return pid;
}

// A started executable: its pid, whether and how it ended, SIGKILL.
class ChildProcess {
 public:
  // The process id (for signals and /proc).
  pid_t pid() const { return pid_; }
  // SIGKILL, then reaps the process.
  void Kill() {
    ::kill(pid_, SIGKILL);
    Wait(std::chrono::seconds(30));
  }
  // Waits up to `timeout` for the exit: its code (-1 while it runs or when
  // a signal ended it).
  int Wait(std::chrono::seconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!exited() && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return exit_code_;
  }
  // True once the process ended (it is reaped here).
  bool exited() {
    if (reaped_) return true;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      reaped_ = true;
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      signal_ = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    }
    return reaped_;
  }
  // The signal that ended the process (0: none or still running).
  int signal() const { return signal_; }

 protected:
  // Starts the process (SpawnLogged).
  void Spawn(std::vector<std::string> argv, const std::string& log, bool truncate = false) {
    pid_ = SpawnLogged(std::move(argv), log, truncate);
  }

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int exit_code_ = -1;
  int signal_ = 0;
};

}  // namespace bsls::testing

#endif  // BSLS_TESTING_SPAWN_H_
