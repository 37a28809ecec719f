// Starting the product's executables from the tests: one fork/exec with the
// child's stdout and stderr in a log file, shared by the launchers of bslsd
// (tests/daemon/daemon_process.h) and bsls-processd
// (tests/processing/processd_process.h).
#ifndef BSLS_TESTING_SPAWN_H_
#define BSLS_TESTING_SPAWN_H_

#include <fcntl.h>
#include <unistd.h>

#include <string>
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

}  // namespace bsls::testing

#endif  // BSLS_TESTING_SPAWN_H_
