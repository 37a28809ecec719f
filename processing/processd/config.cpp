#include "config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <thread>

#include "bsls/config/config_document.h"
#include "bsls/rpc/tls.h"

namespace bsls::processd {
namespace {

Config Parse(const YAML::Node& root) {
  Config c;
  OnlyKeys(root, "",
           {"listen", "workers", "queue", "calibration_cache_entries", "replica", "scratch_dir",
            "max_upload_bytes", "max_frame_pixels", "drain_timeout_ms", "log_level"});
  const YAML::Node listen = root["listen"];
  std::set<std::string> listen_keys = {
      "unix_socket", "tcp",           "plaintext_loopback",        "tls_certificate",
      "tls_key",     "tls_client_ca", "max_receive_message_bytes", "max_send_message_bytes"};
  for (const auto& key : rpc::ConnectionLimitKeys()) listen_keys.insert(key.name);
  for (const auto& key : rpc::Http2LimitKeys()) listen_keys.insert(key.name);
  for (const auto& key : rpc::Http2GuardLimitKeys()) listen_keys.insert(key.name);
  OnlyKeys(listen, "listen", listen_keys);
  if (listen) {
    ListenConfig& l = c.listen;
    ReadKey(listen, "listen", "unix_socket", l.unix_socket);
    ReadKey(listen, "listen", "tcp", l.tcp);
    ReadKey(listen, "listen", "plaintext_loopback", l.plaintext_loopback);
    ReadKey(listen, "listen", "tls_certificate", l.tls_certificate);
    ReadKey(listen, "listen", "tls_key", l.tls_key);
    ReadKey(listen, "listen", "tls_client_ca", l.tls_client_ca);
    ReadKeyInRange(listen, "listen", "max_receive_message_bytes", l.max_receive_message_bytes,
                   1 << 20, 1 << 30);
    ReadKeyInRange(listen, "listen", "max_send_message_bytes", l.max_send_message_bytes, 2 << 20,
                   1 << 30);
    ReadKeysInRange(listen, "listen", rpc::ConnectionLimitKeys(), l.connections);
    ReadKeysInRange(listen, "listen", rpc::Http2LimitKeys(), l.http2);
    ReadKeysInRange(listen, "listen", rpc::Http2GuardLimitKeys(), l.guard);
  }
  ReadKeyInRange(root, "", "workers", c.workers, 0, 256);
  ReadKeyInRange(root, "", "queue", c.queue, -1, 4096);
  ReadKeyInRange(root, "", "calibration_cache_entries", c.calibration_cache_entries, 1, 100000);
  ReadKey(root, "", "replica", c.replica);
  ReadKey(root, "", "scratch_dir", c.scratch_dir);
  ReadKeyInRange(root, "", "max_upload_bytes", c.max_upload_bytes, std::uint64_t{1} << 20,
                 std::uint64_t{64} << 30);
  ReadKeyInRange(root, "", "max_frame_pixels", c.max_frame_pixels, std::int64_t{512} * 512,
                 std::int64_t{4096} * 4096);
  ReadKeyInRange(root, "", "drain_timeout_ms", c.drain_timeout_ms, 0, 600000);
  ReadKey(root, "", "log_level", c.log_level);
  return c;
}

}  // namespace

Config LoadConfig(const std::optional<std::string>& path,
                  const std::vector<std::string>& overrides) {
  const std::string where = "configuration" + (path ? " " + *path : std::string());
  try {
    Config config = Parse(LoadConfigDocument(path, overrides));
    Validate(config);
    return config;
  } catch (const ConfigKeyError& e) {
    throw ConfigError(e.key().empty() ? e.what() : where + ": " + e.what());
  } catch (const YAML::Exception& e) {
    throw ConfigError(where + ": " + e.what());
  }
}

void Validate(const Config& c) {
  const ListenConfig& l = c.listen;
  if (l.unix_socket.empty() && l.tcp.empty())
    throw ConfigError("configuration: listen: give listen.unix_socket or listen.tcp (or both)");
  if (!l.tcp.empty()) {
    const bool tls = !l.tls_certificate.empty() || !l.tls_key.empty() || !l.tls_client_ca.empty();
    if (l.plaintext_loopback && tls)
      throw ConfigError("configuration: listen.plaintext_loopback: excludes the TLS files");
    if (l.plaintext_loopback && !rpc::IsLoopbackTarget(l.tcp))
      throw ConfigError("configuration: listen.tcp " + l.tcp +
                        ": plain TCP is only for loopback addresses (127.0.0.1, [::1], "
                        "localhost); other addresses need mutual TLS");
    if (!l.plaintext_loopback &&
        (l.tls_certificate.empty() || l.tls_key.empty() || l.tls_client_ca.empty()))
      throw ConfigError("configuration: listen.tcp " + l.tcp +
                        ": TCP is mutual TLS only: give listen.tls_certificate, listen.tls_key "
                        "and listen.tls_client_ca");
  }
  if (l.connections.max_connections_per_user > l.connections.max_connections)
    throw ConfigError(
        "configuration: listen.max_connections_per_user is above listen.max_connections");
  if (l.connections.max_tcp_connections_per_peer > l.connections.max_tcp_connections)
    throw ConfigError(
        "configuration: listen.max_tcp_connections_per_peer is above listen.max_tcp_connections");
  if (const std::string why = rpc::Http2GuardLimitsError(l.guard); !why.empty())
    throw ConfigError("configuration: " + why);
  static const std::set<std::string> levels = {"trace", "debug", "info", "warn", "error", "off"};
  if (!levels.count(c.log_level))
    throw ConfigError("configuration: log_level '" + c.log_level +
                      "' is not trace, debug, info, warn, error or off");
  if (!c.scratch_dir.empty() && !std::filesystem::is_directory(c.scratch_dir))
    throw ConfigError("configuration: scratch_dir " + c.scratch_dir + ": is not a folder");
}

int Workers(const Config& c) {
  return c.workers > 0 ? c.workers : std::max(1u, std::thread::hardware_concurrency());
}

int Queue(const Config& c) { return c.queue >= 0 ? c.queue : 2 * Workers(c); }

std::string Dump(const Config& c) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "listen" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "unix_socket" << YAML::Value << c.listen.unix_socket;
  out << YAML::Key << "tcp" << YAML::Value << c.listen.tcp;
  out << YAML::Key << "plaintext_loopback" << YAML::Value << c.listen.plaintext_loopback;
  out << YAML::Key << "tls_certificate" << YAML::Value << c.listen.tls_certificate;
  out << YAML::Key << "tls_key" << YAML::Value << c.listen.tls_key;
  out << YAML::Key << "tls_client_ca" << YAML::Value << c.listen.tls_client_ca;
  out << YAML::Key << "max_receive_message_bytes" << YAML::Value
      << c.listen.max_receive_message_bytes;
  out << YAML::Key << "max_send_message_bytes" << YAML::Value << c.listen.max_send_message_bytes;
  DumpKeys(out, rpc::ConnectionLimitKeys(), c.listen.connections);
  DumpKeys(out, rpc::Http2LimitKeys(), c.listen.http2);
  DumpKeys(out, rpc::Http2GuardLimitKeys(), c.listen.guard);
  out << YAML::EndMap;
  out << YAML::Key << "workers" << YAML::Value << Workers(c);
  out << YAML::Key << "queue" << YAML::Value << Queue(c);
  out << YAML::Key << "calibration_cache_entries" << YAML::Value << c.calibration_cache_entries;
  out << YAML::Key << "replica" << YAML::Value << c.replica;
  out << YAML::Key << "scratch_dir" << YAML::Value << c.scratch_dir;
  out << YAML::Key << "max_upload_bytes" << YAML::Value << c.max_upload_bytes;
  out << YAML::Key << "max_frame_pixels" << YAML::Value << c.max_frame_pixels;
  out << YAML::Key << "drain_timeout_ms" << YAML::Value << c.drain_timeout_ms;
  out << YAML::Key << "log_level" << YAML::Value << c.log_level;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace bsls::processd
