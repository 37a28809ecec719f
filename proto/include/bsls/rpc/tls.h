// Mutual TLS for the services and their clients: PEM files read and checked,
// and client credentials. The services end TLS themselves
// (bsls/rpc/tls_session.h, from the same files); Unix sockets and loopback
// test set-ups are plain.
//
// Thread-safety: pure functions (and the files).
#ifndef BSLS_RPC_TLS_H_
#define BSLS_RPC_TLS_H_

#include <grpcpp/security/credentials.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace bsls::rpc {

// A TLS file that cannot be used; what() names the setting, the file and why.
class TlsFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The three PEM files of one end, each with the name of the setting that
// gave it (a configuration key or a command-line option) for errors.
struct TlsFiles {
  std::string ca;           // the CA that signs the other end's certificate
  std::string certificate;  // our certificate (chain)
  std::string key;          // its private key
  std::string ca_setting = "tls_ca";
  std::string certificate_setting = "tls_certificate";
  std::string key_setting = "tls_key";

  // True when all three files are named.
  bool complete() const { return !ca.empty() && !certificate.empty() && !key.empty(); }
};

// A service's own TLS files, named by its `listen.tls_client_ca`,
// `listen.tls_certificate` and `listen.tls_key` keys for errors.
TlsFiles ListenTlsFiles(std::string client_ca, std::string certificate, std::string key);

// The text of a PEM file; TlsFileError naming `setting` and `path` when it
// cannot be read or holds no PEM block.
std::string ReadPemFile(const std::string& path, const std::string& setting);

// Client credentials presenting files.certificate and trusting files.ca.
// Throws TlsFileError.
std::shared_ptr<grpc::ChannelCredentials> MutualTlsChannelCredentials(const TlsFiles& files);

// True for "unix:..." and "unix-abstract:..." targets.
bool IsUnixTarget(std::string_view target);

// The host name a server certificate must carry for an "ipv4:"/"ipv6:"
// list of addresses (the first one's host); "" for other targets, whose
// host gRPC checks itself.
std::string TlsServerName(std::string_view target);

// True when every address of a "host:port" target (or an "ipv4:"/"ipv6:"
// list) is on this machine's loopback: localhost, 127.0.0.0/8, [::1].
bool IsLoopbackTarget(std::string_view target);

}  // namespace bsls::rpc

#endif  // BSLS_RPC_TLS_H_
