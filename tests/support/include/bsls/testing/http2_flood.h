// A minimal HTTP/2 client for flood tests (header only): raw frames written
// to a connected socket (the connection preface, SETTINGS, PING, HEADERS
// of a gRPC call, RST_STREAM), and a flood that keeps several connections
// busy with such frames for a while, reading and counting what the server
// answers (PING acknowledgements, GOAWAY) and replacing the connections it
// closes. No TLS: it talks to a plaintext Unix socket or loopback port.
#ifndef BSLS_TESTING_HTTP2_FLOOD_H_
#define BSLS_TESTING_HTTP2_FLOOD_H_

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace bsls::testing::http2 {

// Frame types and flags used here (RFC 9113, section 6).
constexpr std::uint8_t kHeaders = 0x1;
constexpr std::uint8_t kRstStream = 0x3;
constexpr std::uint8_t kSettings = 0x4;
constexpr std::uint8_t kPing = 0x6;
constexpr std::uint8_t kGoAway = 0x7;
constexpr std::uint8_t kAck = 0x1;
constexpr std::uint8_t kEndHeaders = 0x4;
constexpr std::uint32_t kCancel = 0x8;  // RST_STREAM error code

// One frame: the 9-byte header (length, type, flags, stream) and `payload`.
inline std::string Frame(std::uint8_t type, std::uint8_t flags, std::uint32_t stream,
                         std::string_view payload) {
  const auto length = static_cast<std::uint32_t>(payload.size());
  std::string frame = {static_cast<char>(length >> 16), static_cast<char>(length >> 8),
                       static_cast<char>(length),       static_cast<char>(type),
                       static_cast<char>(flags),        static_cast<char>((stream >> 24) & 0x7f),
                       static_cast<char>(stream >> 16), static_cast<char>(stream >> 8),
                       static_cast<char>(stream)};
  frame.append(payload);
  return frame;
}

// The client connection preface followed by an empty SETTINGS frame.
inline std::string Preface() {
  return std::string("PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n") + Frame(kSettings, 0, 0, "");
}

// A PING (not an acknowledgement) carrying `opaque`.
inline std::string Ping(std::uint64_t opaque) {
  std::string data(8, '\0');
  for (int i = 0; i < 8; ++i) data[i] = static_cast<char>(opaque >> (56 - 8 * i));
  return Frame(kPing, 0, 0, data);
}

// An HPACK literal header field without indexing, its name taken from the
// static table entry `name_index` (< 15), its value not Huffman-coded (< 127 bytes).
inline std::string LiteralField(int name_index, std::string_view value) {
  std::string field = {static_cast<char>(name_index), static_cast<char>(value.size())};
  field.append(value);
  return field;
}

// HEADERS opening stream `stream` with a gRPC call of `path` (POST, http,
// content-type application/grpc, te trailers), headers complete, the
// request body still to come.
inline std::string CallHeaders(std::uint32_t stream, std::string_view path) {
  std::string block;
  block += static_cast<char>(0x83);       // :method POST (static table 3)
  block += static_cast<char>(0x86);       // :scheme http (6)
  block += LiteralField(4, path);         // :path
  block += LiteralField(1, "localhost");  // :authority
  // content-type: static table 31, whose index needs the 4-bit prefix's continuation.
  block += std::string("\x0f\x10", 2) + static_cast<char>(16) + "application/grpc";
  block += std::string("\x00\x02te\x08trailers", 13);
  return Frame(kHeaders, kEndHeaders, stream, block);
}

// RST_STREAM of `stream` with error CANCEL.
inline std::string Reset(std::uint32_t stream) {
  const std::string code = {0, 0, 0, static_cast<char>(kCancel)};
  return Frame(kRstStream, 0, stream, code);
}

// What a flood sent and what the server answered.
struct FloodCounts {
  long connections = 0;  // opened (the server may close and the flood reopen)
  long frames = 0;       // frames written after the prefaces (whole batches)
  long ping_acks = 0;    // PING acknowledgements received
  long goaways = 0;      // GOAWAY frames received
  long bytes_read = 0;   // everything the server sent
};

// Reads what `fd` has (without waiting) and counts its frames into
// `counts`; `pending` keeps a frame cut between reads. False when the server
// closed the connection.
inline bool ReadAnswers(int fd, std::string* pending, FloodCounts* counts) {
  char buffer[16384];
  for (;;) {
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n == 0) return false;
    if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    counts->bytes_read += n;
    pending->append(buffer, static_cast<std::size_t>(n));
    std::size_t at = 0;
    while (pending->size() - at >= 9) {
      const auto* h = reinterpret_cast<const unsigned char*>(pending->data() + at);
      const std::size_t length = (std::size_t{h[0]} << 16) | (std::size_t{h[1]} << 8) | h[2];
      if (pending->size() - at < 9 + length) break;
      if (h[3] == kPing && (h[4] & kAck) != 0) ++counts->ping_acks;
      if (h[3] == kGoAway) ++counts->goaways;
      at += 9 + length;
    }
    pending->erase(0, at);
  }
}

// Writes all of `bytes` to `fd` (non-blocking), reading the server's
// answers whenever the socket is full so that neither side stalls; false
// when the connection is gone or `until` has passed.
inline bool WriteAll(int fd, std::string_view bytes, std::string* pending, FloodCounts* counts,
                     std::chrono::steady_clock::time_point until) {
  while (!bytes.empty()) {
    const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n > 0) {
      bytes.remove_prefix(static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return false;
    if (!ReadAnswers(fd, pending, counts) || std::chrono::steady_clock::now() >= until)
      return false;
    pollfd wait{fd, POLLIN | POLLOUT, 0};
    ::poll(&wait, 1, 50);
  }
  return ReadAnswers(fd, pending, counts);
}

// Floods for `duration` over `connections` connections at once, each made
// by `connect` (a connected socket, or -1) and given the preface; then,
// until the time is up, each writes what `batch` returns (it is told the
// next free client stream id and moves it on). A connection the server
// closes is replaced. Returns the counts of all connections together.
inline FloodCounts Flood(const std::function<int()>& connect,
                         const std::function<std::string(std::uint32_t* next_stream)>& batch,
                         int connections, std::chrono::milliseconds duration) {
  const auto until = std::chrono::steady_clock::now() + duration;
  std::vector<FloodCounts> each(static_cast<std::size_t>(connections));
  std::vector<std::thread> threads;
  for (FloodCounts& counts : each)
    threads.emplace_back([&connect, &batch, &counts, until] {
      while (std::chrono::steady_clock::now() < until) {
        const int fd = connect();
        if (fd < 0) {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
          continue;
        }
        ++counts.connections;
        std::string pending;
        std::uint32_t next_stream = 1;
        bool open = WriteAll(fd, Preface(), &pending, &counts, until);
        while (open && std::chrono::steady_clock::now() < until) {
          const std::string frames = batch(&next_stream);
          open = WriteAll(fd, frames, &pending, &counts, until);
          for (std::size_t at = 0; open && at + 9 <= frames.size();) {  // count them once sent
            const auto* h = reinterpret_cast<const unsigned char*>(frames.data() + at);
            at += 9 + ((std::size_t{h[0]} << 16) | (std::size_t{h[1]} << 8) | h[2]);
            ++counts.frames;
          }
          if (next_stream >= (1u << 30)) break;  // stream ids run out: a new connection
        }
        ::close(fd);
      }
    });
  for (std::thread& thread : threads) thread.join();
  FloodCounts total;
  for (const FloodCounts& counts : each) {
    total.connections += counts.connections;
    total.frames += counts.frames;
    total.ping_acks += counts.ping_acks;
    total.goaways += counts.goaways;
    total.bytes_read += counts.bytes_read;
  }
  return total;
}

}  // namespace bsls::testing::http2

#endif  // BSLS_TESTING_HTTP2_FLOOD_H_
