#include "config.h"

#include <grp.h>
#include <pwd.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "bsls/config/config_document.h"
#include "bsls/rpc/tls.h"

namespace bsls::bslsd {

namespace {

[[noreturn]] void Fail(const std::string& key, const std::string& reason) {
  throw ConfigKeyError(key, reason);
}

template <typename T>
void Read(const YAML::Node& parent, const std::string& where, const char* key, T& out) {
  ReadKey(parent, where, key, out);
}

template <typename Number>
void ReadInRange(const YAML::Node& parent, const std::string& where, const char* key, Number& out,
                 Number min, Number max) {
  ReadKeyInRange(parent, where, key, out, min, max);
}

service::Role RoleFrom(const std::string& key, const std::string& text) {
  std::optional<service::Role> role = service::ParseRole(text);
  if (!role) Fail(key, "'" + text + "' is not a role (none, viewer, operator, admin)");
  return *role;
}

void ParseFramestore(const YAML::Node& node, FramestoreConfig& out) {
  OnlyKeys(node, "framestore",
           {"backend", "isa_base", "isa_port_access", "simulated_noise_sigma",
            "simulated_frame_rate_hz", "simulated_breathing_mm"});
  if (!node) return;
  if (node["backend"]) {
    const std::string backend = node["backend"].as<std::string>();
    if (backend == "simulated")
      out.backend = Backend::kSimulated;
    else if (backend == "isa")
      out.backend = Backend::kIsa;
    else if (backend == "emulated-isa")
      out.backend = Backend::kEmulatedIsa;
    else if (backend == "usb")
      out.backend = Backend::kUsb;
    else if (backend == "emulated-usb")
      out.backend = Backend::kEmulatedUsb;
    else
      Fail("framestore.backend",
           "'" + backend + "' is not simulated, isa, emulated-isa, usb or emulated-usb");
  }
  int base = out.isa_base;
  ReadInRange(node, "framestore", "isa_base", base, 0x100, 0x3FC);
  out.isa_base = static_cast<std::uint16_t>(base);
  Read(node, "framestore", "isa_port_access", out.isa_port_access);
  if (out.isa_port_access != "dev-port" && out.isa_port_access != "ioperm")
    Fail("framestore.isa_port_access", "'" + out.isa_port_access + "' is not dev-port or ioperm");
  ReadInRange(node, "framestore", "simulated_noise_sigma", out.simulated_noise_sigma, 0.0, 50.0);
  ReadInRange(node, "framestore", "simulated_frame_rate_hz", out.simulated_frame_rate_hz, 1.0,
              200.0);
  ReadInRange(node, "framestore", "simulated_breathing_mm", out.simulated_breathing_mm, 0.0, 5.0);
}

void ParseStore(const YAML::Node& node, store::CaptureStoreOptions& out) {
  OnlyKeys(node, "store",
           {"root", "reserve_mib", "max_total_mib", "max_age_days", "verify_hashes_on_open"});
  if (!node) return;
  Read(node, "store", "root", out.root);
  std::uint64_t reserve = out.free_space_reserve_bytes >> 20;
  ReadInRange<std::uint64_t>(node, "store", "reserve_mib", reserve, 0, 1u << 20);
  out.free_space_reserve_bytes = reserve << 20;
  std::uint64_t total = out.retention.max_total_bytes ? *out.retention.max_total_bytes >> 20 : 0;
  ReadInRange<std::uint64_t>(node, "store", "max_total_mib", total, 0, 1ull << 30);
  out.retention.max_total_bytes = total ? std::optional<std::uint64_t>(total << 20) : std::nullopt;
  int days = out.retention.max_age ? static_cast<int>(out.retention.max_age->count() / 86400) : 0;
  ReadInRange(node, "store", "max_age_days", days, 0, 100000);
  out.retention.max_age =
      days ? std::optional<std::chrono::seconds>(std::chrono::hours(24) * days) : std::nullopt;
  Read(node, "store", "verify_hashes_on_open", out.verify_hashes_on_open);
}

void ParseListen(const YAML::Node& node, ListenConfig& out) {
  std::set<std::string> keys = {
      "unix_socket",           "socket_group", "socket_mode",   "tcp",
      "tls_certificate",       "tls_key",      "tls_client_ca", "max_receive_message_bytes",
      "max_send_message_bytes"};
  for (const auto& key : rpc::ConnectionLimitKeys()) keys.insert(key.name);
  for (const auto& key : rpc::Http2LimitKeys()) keys.insert(key.name);
  for (const auto& key : rpc::Http2GuardLimitKeys()) keys.insert(key.name);
  OnlyKeys(node, "listen", keys);
  if (!node) return;
  Read(node, "listen", "unix_socket", out.unix_socket);
  Read(node, "listen", "socket_group", out.socket_group);
  if (node["socket_mode"]) {
    // Octal, as chmod takes it: "0660" or "660".
    const std::string text = node["socket_mode"].as<std::string>();
    std::size_t used = 0;
    int mode = -1;
    try {
      mode = std::stoi(text, &used, 8);
    } catch (const std::exception&) {
    }
    if (used != text.size() || mode < 0 || mode > 0777)
      Fail("listen.socket_mode", "'" + text + "' is not an octal mode 000..777");
    out.socket_mode = mode;  // a world-writable one is refused by Validate
  }
  ReadKeysInRange(node, "listen", rpc::ConnectionLimitKeys(), out.connections);
  ReadKeysInRange(node, "listen", rpc::Http2LimitKeys(), out.http2);
  ReadKeysInRange(node, "listen", rpc::Http2GuardLimitKeys(), out.guard);
  Read(node, "listen", "tcp", out.tcp);
  Read(node, "listen", "tls_certificate", out.tls_certificate);
  Read(node, "listen", "tls_key", out.tls_key);
  Read(node, "listen", "tls_client_ca", out.tls_client_ca);
  ReadInRange(node, "listen", "max_receive_message_bytes", out.max_receive_message_bytes, 1024,
              1 << 20);
  ReadInRange(node, "listen", "max_send_message_bytes", out.max_send_message_bytes, 1 << 20,
              256 << 20);
}

void ParseRoles(const YAML::Node& node, RolesConfig& out) {
  OnlyKeys(node, "roles", {"admin", "operator", "viewer", "others", "certificates"});
  if (!node) return;
  for (service::Role role :
       {service::Role::kViewer, service::Role::kOperator, service::Role::kAdmin}) {
    const std::string key(service::ToString(role));
    if (!node[key]) continue;
    if (!node[key].IsSequence()) Fail("roles." + key, "must be a list of user names and @groups");
    out.members[role] = node[key].as<std::vector<std::string>>();
  }
  if (node["others"]) out.others = RoleFrom("roles.others", node["others"].as<std::string>());
  if (const YAML::Node certs = node["certificates"]) {
    if (!certs.IsMap()) Fail("roles.certificates", "must map certificate names to roles");
    for (const auto& item : certs) {
      const std::string name = item.first.as<std::string>();
      out.certificates[name] =
          RoleFrom("roles.certificates." + name, item.second.as<std::string>());
    }
  }
}

void ParseLimits(const YAML::Node& node, Config& out) {
  OnlyKeys(node, "limits",
           {"max_preview_streams", "max_event_streams", "default_deadline_ms", "max_deadline_ms",
            "drain_timeout_ms", "stream_write_timeout_ms"});
  if (!node) return;
  ReadInRange(node, "limits", "max_preview_streams", out.limits.max_preview_streams, 1, 256);
  ReadInRange(node, "limits", "max_event_streams", out.limits.max_event_streams, 1, 1024);
  long long ms = out.limits.default_deadline.count();
  ReadInRange(node, "limits", "default_deadline_ms", ms, 100LL, 600000LL);
  out.limits.default_deadline = std::chrono::milliseconds(ms);
  ms = out.limits.max_deadline.count();
  ReadInRange(node, "limits", "max_deadline_ms", ms, 100LL, 3600000LL);
  out.limits.max_deadline = std::chrono::milliseconds(ms);
  ms = out.drain_timeout.count();
  ReadInRange(node, "limits", "drain_timeout_ms", ms, 0LL, 600000LL);
  out.drain_timeout = std::chrono::milliseconds(ms);
  ms = out.limits.stream_write_timeout.count();
  ReadInRange(node, "limits", "stream_write_timeout_ms", ms, 100LL, 600000LL);
  out.limits.stream_write_timeout = std::chrono::milliseconds(ms);
}

void ParseSlides(const YAML::Node& node, SlidesConfig& out) {
  OnlyKeys(node, "slides",
           {"backend", "chip", "advance_line", "select0_line", "select1_line", "in_place_line",
            "lamp_line", "focus_in_line", "focus_out_line", "active_low", "pulse_ms", "settle_ms",
            "change_timeout_ms", "focus_step_ms", "initial_slide", "emulated_travel_ms"});
  if (!node) return;
  if (node["backend"]) {
    const std::string backend = node["backend"].as<std::string>();
    if (backend == "none")
      out.backend = SlideBackend::kNone;
    else if (backend == "simulated")
      out.backend = SlideBackend::kSimulated;
    else if (backend == "gpio")
      out.backend = SlideBackend::kGpio;
    else
      Fail("slides.backend", "'" + backend + "' is not none, simulated or gpio");
  }
  slides::SlideControllerConfig& c = out.controller;
  Read(node, "slides", "chip", c.chip);
  auto line = [&node](const char* key, unsigned& value) {
    ReadInRange(node, "slides", key, value, 0u, 1023u);
  };
  line("advance_line", c.advance_line);
  line("in_place_line", c.in_place_line);
  line("lamp_line", c.lamp_line);
  line("focus_in_line", c.focus_in_line);
  line("focus_out_line", c.focus_out_line);
  for (const char* key : {"select0_line", "select1_line"}) {
    if (!node[key]) continue;
    unsigned value = 0;
    line(key, value);
    (std::string(key) == "select0_line" ? c.select0_line : c.select1_line) = value;
  }
  Read(node, "slides", "active_low", c.active_low);
  auto ms = [&node](const char* key, std::chrono::milliseconds& value) {
    long long count = value.count();
    ReadInRange(node, "slides", key, count, 0LL, 600000LL);
    value = std::chrono::milliseconds(count);
  };
  ms("pulse_ms", c.pulse);
  ms("settle_ms", c.settle);
  ms("change_timeout_ms", c.change_timeout);
  ms("focus_step_ms", c.focus_step);
  ms("emulated_travel_ms", c.emulated_travel);
  ReadInRange(node, "slides", "initial_slide", c.initial_slide, 1, 3);
}

void ParseProcessing(const YAML::Node& node, ProcessingConfig& out) {
  OnlyKeys(node, "processing",
           {"server", "tls_ca", "tls_certificate", "tls_key", "calibration_left",
            "calibration_right", "timeout_ms", "retry_initial_ms", "retry_max_ms"});
  if (!node) return;
  Read(node, "processing", "server", out.server);
  Read(node, "processing", "tls_ca", out.tls_ca);
  Read(node, "processing", "tls_certificate", out.tls_certificate);
  Read(node, "processing", "tls_key", out.tls_key);
  Read(node, "processing", "calibration_left", out.calibration_left);
  Read(node, "processing", "calibration_right", out.calibration_right);
  ReadInRange(node, "processing", "timeout_ms", out.timeout_ms, 100, 3600000);
  ReadInRange(node, "processing", "retry_initial_ms", out.retry_initial_ms, 10, 600000);
  ReadInRange(node, "processing", "retry_max_ms", out.retry_max_ms, 10, 3600000);
}

Config Parse(const YAML::Node& root) {
  Config config = DefaultConfig();
  if (!root || root.IsNull()) return config;
  OnlyKeys(root, "",
           {"framestore", "store", "listen", "roles", "slides", "processing", "limits", "user",
            "log_level"});
  ParseFramestore(root["framestore"], config.framestore);
  ParseStore(root["store"], config.store);
  ParseListen(root["listen"], config.listen);
  ParseRoles(root["roles"], config.roles);
  ParseSlides(root["slides"], config.slides);
  ParseProcessing(root["processing"], config.processing);
  ParseLimits(root["limits"], config);
  Read(root, "", "user", config.user);
  if (config.user.empty()) Fail("user", "is empty: name the account bslsd runs as (e.g. bsls)");
  Read(root, "", "log_level", config.log_level);
  return config;
}

}  // namespace

Config DefaultConfig() {
  Config config;
  config.store.root = "/var/lib/bsls/captures";
  return config;
}

Result<Config> LoadConfig(const std::optional<std::string>& path,
                          const std::vector<std::string>& overrides) {
  YAML::Node root;
  try {
    root = LoadConfigDocument(path, overrides);
  } catch (const ConfigKeyError& e) {
    return Status(e.missing_file() ? ErrorCode::kNotFound : ErrorCode::kInvalidArgument, e.what());
  }
  try {
    Config config = Parse(root);
    if (Status status = Validate(config); !status.ok()) return status;
    return config;
  } catch (const ConfigKeyError& e) {
    return Status(ErrorCode::kInvalidArgument,
                  "configuration" + (path ? " " + *path : std::string()) + ": " + e.what());
  } catch (const YAML::Exception& e) {
    return Status(ErrorCode::kInvalidArgument,
                  "configuration" + (path ? " " + *path : std::string()) + ": " + e.what());
  }
}

Status Validate(const Config& config) {
  auto fail = [](const std::string& message) {
    return Status(ErrorCode::kInvalidArgument, "configuration: " + message);
  };
  std::string error;
  if (!config.store.IsValid(&error)) return fail("store: " + error);
  if (config.listen.socket_mode & 0002) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", config.listen.socket_mode);
    return fail(std::string("listen.socket_mode: '") + mode +
                "' lets every local user connect (world-writable); give the callers a group "
                "(listen.socket_group) and a mode such as 0660");
  }
  if (config.listen.connections.max_connections_per_user >
      config.listen.connections.max_connections)
    return fail("listen.max_connections_per_user is above listen.max_connections");
  if (config.listen.connections.max_tcp_connections_per_peer >
      config.listen.connections.max_tcp_connections)
    return fail("listen.max_tcp_connections_per_peer is above listen.max_tcp_connections");
  if (const std::string why = rpc::Http2GuardLimitsError(config.listen.guard); !why.empty())
    return fail(why);
  if (config.listen.unix_socket.empty() && config.listen.tcp.empty())
    return fail("listen.unix_socket and listen.tcp are both empty: nobody could connect");
  if (!config.listen.tcp.empty() &&
      (config.listen.tls_certificate.empty() || config.listen.tls_key.empty() ||
       config.listen.tls_client_ca.empty()))
    return fail(
        "listen.tcp is set, so listen.tls_certificate, listen.tls_key and "
        "listen.tls_client_ca are required (TCP is mutual TLS only)");
  if (config.limits.default_deadline > config.limits.max_deadline)
    return fail("limits.default_deadline_ms is above limits.max_deadline_ms");
  if (config.slides.backend != SlideBackend::kNone) {
    if (Status status = slides::Validate(config.slides.controller); !status.ok())
      return fail("slides: " + status.message());
  }
  const ProcessingConfig& p = config.processing;
  const bool tls = !p.tls_ca.empty() || !p.tls_certificate.empty() || !p.tls_key.empty();
  if (tls && (p.tls_ca.empty() || p.tls_certificate.empty() || p.tls_key.empty()))
    return fail("processing: give all of tls_ca, tls_certificate and tls_key, or none");
  if (!p.server.empty() && !tls && !rpc::IsUnixTarget(p.server) && !rpc::IsLoopbackTarget(p.server))
    return fail("processing.server " + p.server +
                " is another machine: mutual TLS only (give processing.tls_ca, "
                "processing.tls_certificate and processing.tls_key)");
  if (p.retry_initial_ms > p.retry_max_ms)
    return fail("processing.retry_initial_ms is above processing.retry_max_ms");
  return {};
}

Result<service::RolePolicy> ResolveRoles(const RolesConfig& roles) {
  service::RolePolicy policy;
  policy.others = roles.others;
  policy.certificate_names = roles.certificates;
  for (const auto& [role, members] : roles.members) {
    for (const std::string& member : members) {
      const std::string key = "roles." + std::string(service::ToString(role));
      if (!member.empty() && member[0] == '@') {
        group* entry = ::getgrnam(member.c_str() + 1);
        if (entry == nullptr)
          return Status(ErrorCode::kInvalidArgument,
                        key + ": group '" + member.substr(1) + "' does not exist on this machine");
        auto& slot = policy.groups[entry->gr_gid];
        slot = std::max(slot, role);
      } else {
        passwd* entry = ::getpwnam(member.c_str());
        uid_t uid;
        if (entry != nullptr) {
          uid = entry->pw_uid;
        } else if (!member.empty() && member.find_first_not_of("0123456789") == std::string::npos) {
          uid = static_cast<uid_t>(std::stoul(member));  // a numeric uid without a name
        } else {
          return Status(ErrorCode::kInvalidArgument,
                        key + ": user '" + member + "' does not exist on this machine");
        }
        auto& slot = policy.users[uid];
        slot = std::max(slot, role);
      }
    }
  }
  return policy;
}

std::string Dump(const Config& config) {
  YAML::Emitter out;
  auto backend = [](Backend b) {
    switch (b) {
      case Backend::kSimulated:
        return "simulated";
      case Backend::kIsa:
        return "isa";
      case Backend::kEmulatedIsa:
        return "emulated-isa";
      case Backend::kUsb:
        return "usb";
      case Backend::kEmulatedUsb:
        return "emulated-usb";
    }
    return "?";
  };
  out << YAML::BeginMap;
  out << YAML::Key << "framestore" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "backend" << YAML::Value << backend(config.framestore.backend);
  out << YAML::Key << "isa_base" << YAML::Value << YAML::Hex << config.framestore.isa_base
      << YAML::Dec;
  out << YAML::Key << "isa_port_access" << YAML::Value << config.framestore.isa_port_access;
  out << YAML::Key << "simulated_noise_sigma" << YAML::Value
      << config.framestore.simulated_noise_sigma;
  out << YAML::Key << "simulated_frame_rate_hz" << YAML::Value
      << config.framestore.simulated_frame_rate_hz;
  out << YAML::Key << "simulated_breathing_mm" << YAML::Value
      << config.framestore.simulated_breathing_mm;
  out << YAML::EndMap;
  out << YAML::Key << "store" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "root" << YAML::Value << config.store.root;
  out << YAML::Key << "reserve_mib" << YAML::Value << (config.store.free_space_reserve_bytes >> 20);
  out << YAML::Key << "max_total_mib" << YAML::Value
      << (config.store.retention.max_total_bytes ? *config.store.retention.max_total_bytes >> 20
                                                 : 0);
  out << YAML::Key << "max_age_days" << YAML::Value
      << (config.store.retention.max_age ? config.store.retention.max_age->count() / 86400 : 0);
  out << YAML::Key << "verify_hashes_on_open" << YAML::Value << config.store.verify_hashes_on_open;
  out << YAML::EndMap;
  out << YAML::Key << "listen" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "unix_socket" << YAML::Value << config.listen.unix_socket;
  out << YAML::Key << "socket_group" << YAML::Value << config.listen.socket_group;
  char mode[8];
  std::snprintf(mode, sizeof mode, "%04o", config.listen.socket_mode);
  out << YAML::Key << "socket_mode" << YAML::Value << YAML::DoubleQuoted << mode;
  DumpKeys(out, rpc::ConnectionLimitKeys(), config.listen.connections);
  DumpKeys(out, rpc::Http2LimitKeys(), config.listen.http2);
  DumpKeys(out, rpc::Http2GuardLimitKeys(), config.listen.guard);
  out << YAML::Key << "tcp" << YAML::Value << config.listen.tcp;
  out << YAML::Key << "tls_certificate" << YAML::Value << config.listen.tls_certificate;
  out << YAML::Key << "tls_key" << YAML::Value << config.listen.tls_key;
  out << YAML::Key << "tls_client_ca" << YAML::Value << config.listen.tls_client_ca;
  out << YAML::Key << "max_receive_message_bytes" << YAML::Value
      << config.listen.max_receive_message_bytes;
  out << YAML::Key << "max_send_message_bytes" << YAML::Value
      << config.listen.max_send_message_bytes;
  out << YAML::EndMap;
  out << YAML::Key << "roles" << YAML::Value << YAML::BeginMap;
  for (const auto& [role, members] : config.roles.members)
    out << YAML::Key << std::string(service::ToString(role)) << YAML::Value << YAML::Flow
        << members;
  out << YAML::Key << "others" << YAML::Value
      << std::string(service::ToString(config.roles.others));
  out << YAML::EndMap;
  const ProcessingConfig& p = config.processing;
  out << YAML::Key << "processing" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "server" << YAML::Value << p.server;
  out << YAML::Key << "tls_ca" << YAML::Value << p.tls_ca;
  out << YAML::Key << "tls_certificate" << YAML::Value << p.tls_certificate;
  out << YAML::Key << "tls_key" << YAML::Value << p.tls_key;
  out << YAML::Key << "calibration_left" << YAML::Value << p.calibration_left;
  out << YAML::Key << "calibration_right" << YAML::Value << p.calibration_right;
  out << YAML::Key << "timeout_ms" << YAML::Value << p.timeout_ms;
  out << YAML::Key << "retry_initial_ms" << YAML::Value << p.retry_initial_ms;
  out << YAML::Key << "retry_max_ms" << YAML::Value << p.retry_max_ms;
  out << YAML::EndMap;
  out << YAML::Key << "limits" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "max_preview_streams" << YAML::Value << config.limits.max_preview_streams;
  out << YAML::Key << "max_event_streams" << YAML::Value << config.limits.max_event_streams;
  out << YAML::Key << "default_deadline_ms" << YAML::Value
      << config.limits.default_deadline.count();
  out << YAML::Key << "max_deadline_ms" << YAML::Value << config.limits.max_deadline.count();
  out << YAML::Key << "drain_timeout_ms" << YAML::Value << config.drain_timeout.count();
  out << YAML::Key << "stream_write_timeout_ms" << YAML::Value
      << config.limits.stream_write_timeout.count();
  out << YAML::EndMap;
  out << YAML::Key << "user" << YAML::Value << config.user;
  out << YAML::Key << "log_level" << YAML::Value << config.log_level;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace bsls::bslsd
