// Crash safety: a child process stores two-frame 512x512 grabs as fast as it
// can and reports each id on a pipe only after Put returned (the
// acknowledgement); the parent kills it with SIGKILL at a random moment,
// reopens the store and checks that every acknowledged capture is present
// and its hashes verify, that leftovers of the interrupted put are gone and
// that the index passes its integrity check. Repeated until 200 grabs have
// been acknowledged.
//
// SIGKILL ends the process, not the machine: the page cache survives. Power
// loss is covered by the fsync sequence (docs/capture-store.md) and by the
// fault-injection test failing each fsync.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <set>
#include <thread>

#include "bsls/store/capture_store.h"
#include "store_test_util.h"

namespace bsls::store {
namespace {

using testing::RandomRequest;
using testing::TempDir;
using testing::TestOptions;

constexpr int kGrabsToAcknowledge = 200;
constexpr int kFrameSide = 512;

// The child: stores grabs forever, writing "<id>\n" after each acknowledged one.
[[noreturn]] void RunChild(const std::string& root, int ack_fd, unsigned seed) {
  auto store = CaptureStore::Open(TestOptions(root));
  if (!store.ok()) _exit(2);
  std::mt19937 rng(seed);
  CaptureRequest request = RandomRequest(rng, "crash", "p", kFrameSide, kFrameSide);
  while (true) {
    // New pixels in every grab (cheaply: a few random rows).
    for (auto& frame : request.frames) {
      for (int i = 0; i < 4; ++i) {
        const std::size_t row = rng() % kFrameSide;
        for (int x = 0; x < kFrameSide; ++x) {
          frame.pixels[row * kFrameSide + x] = static_cast<std::uint8_t>(rng());
        }
      }
    }
    auto put = (*store)->Put(request);
    if (!put.ok()) _exit(3);
    const std::string line = put->id.str() + "\n";
    if (::write(ack_fd, line.data(), line.size()) != static_cast<ssize_t>(line.size())) _exit(4);
  }
}

// Reads whole lines from `fd` into `ids` until `wanted` more arrived or EOF.
bool ReadAcks(int fd, std::string& pending, std::set<std::string>& ids, int wanted) {
  int got = 0;
  char buffer[4096];
  while (wanted < 0 || got < wanted) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    pending.append(buffer, static_cast<std::size_t>(n));
    std::size_t newline;
    while ((newline = pending.find('\n')) != std::string::npos) {
      ids.insert(pending.substr(0, newline));
      pending.erase(0, newline + 1);
      ++got;
    }
  }
  return true;
}

TEST(StoreCrashTest, SigkillDuringGrabsLosesNoAcknowledgedCapture) {
  TempDir dir;
  const std::string root = dir.path() + "/store";
  std::mt19937 rng(20240501);
  std::set<std::string> acknowledged;
  int rounds = 0;
  int leftovers_removed = 0;
  const auto start = std::chrono::steady_clock::now();
  while (static_cast<int>(acknowledged.size()) < kGrabsToAcknowledge) {
    ASSERT_LT(rounds, 200) << "the child acknowledges too few grabs";
    ++rounds;
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const unsigned child_seed = static_cast<unsigned>(rng());
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      ::close(fds[0]);
      RunChild(root, fds[1], child_seed);
    }
    ::close(fds[1]);
    // A random moment: after 0..25 acknowledgements, plus 0..8 ms.
    std::string pending;
    const int wait_for = static_cast<int>(rng() % 26);
    ReadAcks(fds[0], pending, acknowledged, wait_for);
    std::this_thread::sleep_for(std::chrono::microseconds(rng() % 8000));
    ::kill(pid, SIGKILL);
    ReadAcks(fds[0], pending, acknowledged, -1);  // everything written before the kill
    ::close(fds[0]);
    int wait_status = 0;
    ASSERT_EQ(::waitpid(pid, &wait_status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(wait_status) && WTERMSIG(wait_status) == SIGKILL)
        << "the child stopped by itself, exit code "
        << (WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1);

    auto store = CaptureStore::Open(TestOptions(root));
    ASSERT_TRUE(store.ok()) << "round " << rounds << ": " << store.status().ToString();
    const RecoveryReport& report = (*store)->recovery_report();
    for (const auto& problem : report.problems) {
      ADD_FAILURE() << "round " << rounds << ": " << problem.status.ToString();
    }
    leftovers_removed += report.temp_files_removed + report.orphan_files_removed;
    ASSERT_TRUE((*store)->CheckIndexIntegrity().ok());
    // Every acknowledged capture is there (a killed, unacknowledged put may
    // have committed too: present but never reported, which is allowed).
    std::set<std::string> listed;
    CaptureFilter all;
    all.page_size = kMaxPageSize;
    while (true) {
      auto page = (*store)->List(all);
      ASSERT_TRUE(page.ok());
      for (const auto& info : page->captures) listed.insert(info.id.str());
      if (page->next_page_token.empty()) break;
      all.page_token = page->next_page_token;
    }
    int lost = 0;
    for (const auto& id : acknowledged) lost += listed.count(id) == 0;
    ASSERT_EQ(lost, 0) << "round " << rounds;
    ASSERT_EQ(static_cast<int>(report.captures_checked), static_cast<int>(listed.size()));
    // No leftovers: exactly two frame files per capture, no temporary files.
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(root + "/frames")) {
      EXPECT_NE(entry.path().filename().string().rfind(".tmp-", 0), 0u) << entry.path();
      ++files;
    }
    EXPECT_EQ(files, 2 * static_cast<int>(listed.size()));
  }
  // Spot-check reads of acknowledged captures through Get (hashes on read).
  auto store = CaptureStore::Open(TestOptions(root));
  ASSERT_TRUE(store.ok());
  int checked = 0;
  for (const auto& id : acknowledged) {
    if (checked++ % 10 != 0) continue;
    auto got = (*store)->Get(id);
    EXPECT_TRUE(got.ok()) << got.status().ToString();
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("rounds", rounds);
  RecordProperty("acknowledged", static_cast<int>(acknowledged.size()));
  RecordProperty("leftovers_removed", leftovers_removed);
  std::printf("[ crash    ] %d kills, %zu grabs acknowledged, %d leftovers removed, %.1f s\n",
              rounds, acknowledged.size(), leftovers_removed, seconds);
}

}  // namespace
}  // namespace bsls::store
