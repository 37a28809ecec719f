// bslsd's configuration: a YAML file (default /etc/bsls/bslsd.yaml; the
// installed example is systemd/bslsd.yaml) with command-line overrides.
// Every value is checked at load; an error names the key and the reason, so
// `bslsd --check-config` tells an administrator exactly what to fix.
#ifndef BSLS_BSLSD_CONFIG_H_
#define BSLS_BSLSD_CONFIG_H_

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bsls/common/status.h"
#include "bsls/rpc/server_limits.h"
#include "bsls/service/capture_service.h"
#include "bsls/service/roles.h"
#include "bsls/slides/slide_controller.h"
#include "bsls/store/capture_store.h"

namespace bsls::bslsd {

// Which framestore backend the daemon opens.
enum class Backend { kSimulated, kIsa, kEmulatedIsa, kUsb, kEmulatedUsb };

struct FramestoreConfig {
  Backend backend = Backend::kSimulated;
  std::uint16_t isa_base = 0x300;            // the card's 8255 (thesis 3.1)
  std::string isa_port_access = "dev-port";  // "dev-port" (/dev/port) or "ioperm"
  double simulated_noise_sigma = 3.0;        // grey levels
  double simulated_frame_rate_hz = 25.0;
  double simulated_breathing_mm = 0.5;  // peak motion of the simulated head; 0: still
};

// Who may do what: user names, "@group" for every member of a group.
struct RolesConfig {
  std::map<service::Role, std::vector<std::string>> members;
  service::Role others = service::Role::kNone;
  std::map<std::string, service::Role> certificates;  // TLS client CN -> role
};

struct ListenConfig {
  std::string unix_socket = "/run/bsls/bslsd.sock";
  // Owning group of the socket, a name or a number ("" : the daemon's group).
  std::string socket_group;
  // Permissions of the socket file; world-writable modes (o+w) are refused:
  // any local user could then call the daemon.
  int socket_mode = 0660;
  rpc::ConnectionLimits connections;  // of the Unix socket and of TCP
  rpc::Http2Limits http2;             // keep-alive, pings, idle connections, streams
  // The Unix socket's frame budgets (rpc::Http2Guard: new streams, resets,
  // pings, settings per second), per connection and in all.
  rpc::Http2GuardLimits guard;
  std::string tcp;              // "host:port" with mutual TLS; "" : no TCP (the default)
  std::string tls_certificate;  // PEM files, required with tcp
  std::string tls_key;
  std::string tls_client_ca;
  int max_receive_message_bytes = 64 * 1024;      // requests are small
  int max_send_message_bytes = 16 * 1024 * 1024;  // a capture with three 8192^2... capped
};

enum class SlideBackend { kNone, kSimulated, kGpio };

struct SlidesConfig {
  SlideBackend backend = SlideBackend::kSimulated;
  slides::SlideControllerConfig controller;  // lines and timing (gpio and simulated)
};

// The processing service every acknowledged grab is handed to.
struct ProcessingConfig {
  // "unix:PATH", "host:port", "ipv4:h:p,h:p" or "dns:///name:port" (round
  // robin over replicas); "" : no processing.
  std::string server;
  std::string tls_ca;  // mutual TLS (required for a server on another machine)
  std::string tls_certificate;
  std::string tls_key;
  std::string calibration_left;  // calibration files (bsls calibrate); "" : none
  std::string calibration_right;
  int timeout_ms = 120000;      // deadline of one call
  int retry_initial_ms = 1000;  // back-off after a failed attempt, doubled
  int retry_max_ms = 60000;     // up to this
};

struct Config {
  FramestoreConfig framestore;
  store::CaptureStoreOptions store;
  ListenConfig listen;
  RolesConfig roles;
  SlidesConfig slides;
  ProcessingConfig processing;
  service::ServiceLimits limits;
  std::chrono::milliseconds drain_timeout{5000};  // SIGTERM: in-flight calls get this long
  // The account bslsd switches to when started as root (a name, or
  // "uid:gid" numbers); started as any other user it keeps that one.
  std::string user = "bsls";
  std::string log_level = "info";
};

// The defaults, with the store under /var/lib/bsls/captures.
Config DefaultConfig();
// The defaults, then the file at `path` (if given), then each "key.path=value"
// override (the same dotted keys as the file, e.g. framestore.backend=usb).
// Unknown keys are errors (a typo must not silently keep a default).
// kNotFound when the file is missing; kInvalidArgument naming the key and why.
Result<Config> LoadConfig(const std::optional<std::string>& path,
                          const std::vector<std::string>& overrides);
// Checks the whole configuration (ranges, TLS completeness); names the first bad key.
Status Validate(const Config& config);
// The role policy of `roles`: user names and groups resolved to ids;
// kInvalidArgument naming an unknown user or group.
Result<service::RolePolicy> ResolveRoles(const RolesConfig& roles);
// The configuration as YAML (what --check-config prints).
std::string Dump(const Config& config);

}  // namespace bsls::bslsd

#endif  // BSLS_BSLSD_CONFIG_H_
