// bsls-processd's configuration: a YAML file (installed example:
// systemd/bsls-processd.yaml) with "key.path=value" overrides. Every value is
// checked at load; an error names the key and the reason. Network access is
// mutual TLS only; plain TCP is accepted only on loopback and only when
// asked for (listen.plaintext_loopback), for tests and one-machine set-ups.
#ifndef BSLS_PROCESSD_CONFIG_H_
#define BSLS_PROCESSD_CONFIG_H_

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bsls/rpc/server_limits.h"

namespace bsls::processd {

// A configuration that cannot be used; what() names the key and the reason.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ListenConfig {
  std::string unix_socket = "/run/bsls-processd/processd.sock";  // "" : none
  std::string tcp;  // "host:port"; mutual TLS unless plaintext_loopback on a loopback host
  bool plaintext_loopback = false;
  std::string tls_certificate;  // PEM files, required for TLS
  std::string tls_key;
  std::string tls_client_ca;
  int max_receive_message_bytes = 40 << 20;  // two 4096^2 frames and their request
  int max_send_message_bytes = 5 << 20;      // artifacts travel in 1 MiB chunks
  rpc::ConnectionLimits connections;         // of the Unix socket and of TCP
  rpc::Http2Limits http2;  // keep-alive, pings, idle connections, streams (same keys)
  // The Unix socket's frame budgets (rpc::Http2Guard), per connection and in all.
  rpc::Http2GuardLimits guard;
};

struct Config {
  ListenConfig listen;
  int workers = 0;  // 0: one per CPU core
  int queue = -1;   // -1: twice the workers
  int calibration_cache_entries = 64;
  std::string replica;      // "" : host:pid
  std::string scratch_dir;  // "" : $TMPDIR or /tmp
  std::uint64_t max_upload_bytes = std::uint64_t{256} << 20;
  // Pixels of one frame (width x height) a call may ask to be worked on,
  // [512^2, 4096^2]: a frame above it is refused with INVALID_ARGUMENT.
  std::int64_t max_frame_pixels = std::int64_t{8} << 20;
  int drain_timeout_ms = 5000;
  std::string log_level = "info";
};

// The defaults, then the file at `path` (if given), then each override.
// Unknown keys are errors. Throws ConfigError.
Config LoadConfig(const std::optional<std::string>& path,
                  const std::vector<std::string>& overrides);
// Checks the whole configuration; throws ConfigError naming the first bad key.
void Validate(const Config& config);
// Workers and queue with the defaults (0, -1) resolved.
int Workers(const Config& config);
int Queue(const Config& config);
// The configuration as YAML (what --check-config prints).
std::string Dump(const Config& config);

}  // namespace bsls::processd

#endif  // BSLS_PROCESSD_CONFIG_H_
