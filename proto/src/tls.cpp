#include "bsls/rpc/tls.h"

#include <arpa/inet.h>

#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

namespace bsls::rpc {

TlsFiles ListenTlsFiles(std::string client_ca, std::string certificate, std::string key) {
  return {std::move(client_ca),   std::move(certificate),   std::move(key),
          "listen.tls_client_ca", "listen.tls_certificate", "listen.tls_key"};
}

std::string ReadPemFile(const std::string& path, const std::string& setting) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TlsFileError(setting + " " + path + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  if (text.str().find("-----BEGIN") == std::string::npos)
    throw TlsFileError(setting + " " + path + ": is not a PEM file");
  return text.str();
}

std::shared_ptr<grpc::ChannelCredentials> MutualTlsChannelCredentials(const TlsFiles& files) {
  grpc::SslCredentialsOptions tls;
  tls.pem_root_certs = ReadPemFile(files.ca, files.ca_setting);
  tls.pem_cert_chain = ReadPemFile(files.certificate, files.certificate_setting);
  tls.pem_private_key = ReadPemFile(files.key, files.key_setting);
  return grpc::SslCredentials(tls);
}

bool IsUnixTarget(std::string_view target) {
  return target.starts_with("unix:") || target.starts_with("unix-abstract:");
}

namespace {

// The host of "host:port", "[v6]:port" or "dns:///host:port".
std::string_view HostOf(std::string_view address) {
  if (address.starts_with("dns:")) {
    address.remove_prefix(4);
    while (address.starts_with("/")) address.remove_prefix(1);
  }
  if (address.starts_with("[")) {
    const size_t close = address.find(']');
    return close == std::string_view::npos ? address : address.substr(1, close - 1);
  }
  const size_t colon = address.rfind(':');
  return colon == std::string_view::npos ? address : address.substr(0, colon);
}

bool IsLoopbackHost(std::string_view host) {
  if (host == "localhost") return true;
  const std::string text(host);
  in_addr v4{};
  if (inet_pton(AF_INET, text.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, text.c_str(), &v6) == 1) return IN6_IS_ADDR_LOOPBACK(&v6);
  return false;
}

}  // namespace

std::string TlsServerName(std::string_view target) {
  if (!target.starts_with("ipv4:") && !target.starts_with("ipv6:")) return "";
  target.remove_prefix(5);
  return std::string(HostOf(target.substr(0, target.find(','))));
}

bool IsLoopbackTarget(std::string_view target) {
  std::vector<std::string_view> addresses;
  if (target.starts_with("ipv4:") || target.starts_with("ipv6:")) {
    target.remove_prefix(5);
    while (!target.empty()) {
      const size_t comma = target.find(',');
      addresses.push_back(target.substr(0, comma));
      if (comma == std::string_view::npos) break;
      target.remove_prefix(comma + 1);
    }
  } else {
    addresses.push_back(target);
  }
  if (addresses.empty()) return false;
  for (std::string_view address : addresses)
    if (!IsLoopbackHost(HostOf(address))) return false;
  return true;
}

}  // namespace bsls::rpc
