// Port access: ranges, the Status type, /dev/port's offset arithmetic on a
// regular file, and the "cannot open without privilege" path of both real
// mechanisms (run in a child process that dropped every capability; real
// ports are never touched).
#include "bsls/framestore/port_io.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/capability.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "bsls/framestore/dev_port_io.h"
#include "bsls/framestore/framestore.h"
#include "bsls/framestore/ioperm_port_io.h"

namespace bsls::framestore {
namespace {

constexpr PortRange kCard{0x300, 4};

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(PortRangeTest, ContainsAndValidity) {
  EXPECT_TRUE(kCard.Contains(0x300));
  EXPECT_TRUE(kCard.Contains(0x303));
  EXPECT_FALSE(kCard.Contains(0x304));
  EXPECT_FALSE(kCard.Contains(0x2FF));
  EXPECT_TRUE(kCard.Contains(0x300, 4));
  EXPECT_FALSE(kCard.Contains(0x301, 4));
  EXPECT_EQ(kCard.ToString(), "0x300-0x303");
  std::string error;
  EXPECT_TRUE(kCard.IsValid(&error));
  EXPECT_FALSE((PortRange{0x300, 0}).IsValid(&error));
  EXPECT_TRUE(Contains(error, "empty"));
  EXPECT_FALSE((PortRange{0xFFFE, 4}).IsValid(&error));
  EXPECT_TRUE(Contains(error, "beyond"));
  EXPECT_TRUE(kAllPorts.Contains(0xFFFF));
}

TEST(StatusTest, CodesAndMessages) {
  EXPECT_TRUE(Status().ok());
  const Status status(ErrorCode::kDeadlineExceeded, "OE stayed high");
  EXPECT_FALSE(status.ok());
  EXPECT_EQ(status.ToString(), "deadline exceeded: OE stayed high");
  Result<int> value(3);
  EXPECT_TRUE(value.ok());
  EXPECT_EQ(*value, 3);
  Result<int> error(Status(ErrorCode::kUnavailable, "gone"));
  EXPECT_FALSE(error.ok());
  EXPECT_EQ(error.status().code(), ErrorCode::kUnavailable);
}

TEST(CameraTest, NamesRoundTrip) {
  for (Camera camera : {Camera::kLeft, Camera::kRight, Camera::kThird}) {
    EXPECT_EQ(ParseCamera(ToString(camera)), camera);
  }
  EXPECT_EQ(ParseCamera("centre"), std::nullopt);
  EXPECT_EQ(ParsePortAccess("ioperm"), PortAccess::kIoperm);
  EXPECT_EQ(ParsePortAccess("dev-port"), PortAccess::kDevPort);
  EXPECT_EQ(ParsePortAccess("mmio"), std::nullopt);
}

TEST(DevPortIoTest, MissingDeviceIsUnavailableAndNamesThePath) {
  auto io = DevPortIo::Open(kCard, "/nonexistent/port");
  ASSERT_FALSE(io.ok());
  EXPECT_EQ(io.status().code(), ErrorCode::kUnavailable);
  EXPECT_TRUE(Contains(io.status().message(), "/nonexistent/port")) << io.status().message();
  EXPECT_TRUE(Contains(io.status().message(), "0x300-0x303")) << io.status().message();
  EXPECT_TRUE(Contains(io.status().message(), "ENOENT")) << io.status().message();
}

// /dev/port is a file whose offset is the port number; a regular file shows
// that the byte goes to and comes from exactly that offset.
TEST(DevPortIoTest, AccessesTheByteAtThePortOffset) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("bsls_dev_port_" + std::to_string(getpid()));
  {
    const int fd = ::open(path.c_str(), O_CREAT | O_TRUNC | O_RDWR, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, 0x400), 0);
    ::close(fd);
  }
  auto io = DevPortIo::Open(kCard, path.string());
  ASSERT_TRUE(io.ok()) << io.status().ToString();
  (*io)->Outb(0x302, 0x5A);
  (*io)->Outb(0x303, 0x93);
  EXPECT_EQ((*io)->Inb(0x302), 0x5A);
  EXPECT_EQ((*io)->Inb(0x303), 0x93);
  EXPECT_EQ((*io)->Inb(0x300), 0x00);
  EXPECT_TRUE((*io)->status().ok());
  FILE* file = std::fopen(path.c_str(), "rb");
  ASSERT_NE(file, nullptr);
  std::fseek(file, 0x302, SEEK_SET);
  EXPECT_EQ(std::fgetc(file), 0x5A);
  std::fclose(file);
  std::filesystem::remove(path);
}

// Runs `open` in a child process without any capability; returns the
// child's Status as "<code>|<message>".
std::string OpenWithoutPrivilege(Result<std::unique_ptr<PortIo>> (*open)()) {
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return "pipe failed";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipe_fds[0]);
    __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
    __user_cap_data_struct data[_LINUX_CAPABILITY_U32S_3] = {};
    std::string report;
    if (syscall(SYS_capset, &header, data) != 0) {
      report = "capset failed";
    } else {
      auto io = open();
      report = io.ok() ? std::string("opened")
                       : std::to_string(int(io.status().code())) + "|" + io.status().message();
    }
    [[maybe_unused]] ssize_t n = ::write(pipe_fds[1], report.data(), report.size());
    ::_exit(0);
  }
  ::close(pipe_fds[1]);
  std::string report;
  char buffer[512];
  ssize_t n;
  while ((n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0) report.append(buffer, n);
  ::close(pipe_fds[0]);
  int wstatus = 0;
  ::waitpid(pid, &wstatus, 0);
  return report;
}

std::string CodeOf(ErrorCode code) { return std::to_string(int(code)) + "|"; }

TEST(PrivilegeTest, IopermWithoutCapSysRawioIsPermissionDenied) {
#if defined(__x86_64__) || defined(__i386__)
  const std::string report =
      OpenWithoutPrivilege([] { return OpenPortIo(PortAccess::kIoperm, kCard); });
  ASSERT_NE(report, "opened") << "ioperm succeeded without capabilities";
  EXPECT_TRUE(Contains(report, "ioperm(0x300-0x303) failed")) << report;
  if (report.rfind(CodeOf(ErrorCode::kPermissionDenied), 0) == 0) {
    EXPECT_TRUE(Contains(report, "CAP_SYS_RAWIO") || Contains(report, "locked down")) << report;
  } else {
    // A sandbox (gVisor, some seccomp profiles) without ioperm at all.
    EXPECT_EQ(report.rfind(CodeOf(ErrorCode::kUnavailable), 0), 0u) << report;
    EXPECT_TRUE(Contains(report, "does not implement ioperm")) << report;
  }
#else
  auto io = OpenPortIo(PortAccess::kIoperm, kCard);
  ASSERT_FALSE(io.ok());
  EXPECT_EQ(io.status().code(), ErrorCode::kUnavailable);
  EXPECT_TRUE(Contains(io.status().message(), "only on x86"));
#endif
}

TEST(PrivilegeTest, DevPortWithoutCapSysRawioFailsClearly) {
  const std::string report =
      OpenWithoutPrivilege([] { return OpenPortIo(PortAccess::kDevPort, kCard); });
  ASSERT_NE(report, "opened") << "/dev/port opened without capabilities";
  EXPECT_TRUE(Contains(report, "cannot open /dev/port for ports 0x300-0x303")) << report;
  if (report.rfind(CodeOf(ErrorCode::kPermissionDenied), 0) == 0) {
    EXPECT_TRUE(Contains(report, "CAP_SYS_RAWIO") || Contains(report, "locked down") ||
                Contains(report, "root:kmem"))
        << report;
  } else {
    // This machine has no /dev/port at all: the message must say so.
    EXPECT_EQ(report.rfind(CodeOf(ErrorCode::kUnavailable), 0), 0u) << report;
    EXPECT_TRUE(Contains(report, "CONFIG_DEVPORT")) << report;
  }
}

}  // namespace
}  // namespace bsls::framestore
