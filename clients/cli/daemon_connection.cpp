#include "daemon_connection.h"

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace bsls::cli {

namespace {

constexpr const char* kSystemSocket = "unix:/run/bsls/bslsd.sock";

std::string ReadPem(const std::string& path, const std::string& option) {
  std::ifstream in(path);
  if (!in) throw CommandError(kExitInput, option + " " + path + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  if (text.str().find("-----BEGIN") == std::string::npos)
    throw CommandError(kExitInput, option + " " + path + ": is not a PEM file");
  return text.str();
}

bool IsUnix(const std::string& target) { return target.rfind("unix:", 0) == 0; }

}  // namespace

void AddDaemonOptions(CLI::App& command, ServiceAddress& address) {
  const char* from_env = std::getenv("BSLS_DAEMON");
  address.target = from_env != nullptr && *from_env != '\0' ? from_env : kSystemSocket;
  command.add_option("--daemon", address.target,
                     "the capture daemon: unix:PATH, or HOST:PORT with mutual TLS "
                     "(default $BSLS_DAEMON, else unix:/run/bsls/bslsd.sock)");
  command.add_option("--tls-ca", address.tls_ca, "CA certificate (PEM) that signed the service's");
  command.add_option("--tls-cert", address.tls_certificate, "our client certificate (PEM)");
  command.add_option("--tls-key", address.tls_key, "its private key (PEM)");
  command.add_option("--timeout", address.timeout_s, "seconds each call may take")
      ->check(CLI::Range(0.1, 3600.0));
}

std::shared_ptr<grpc::Channel> OpenChannel(const ServiceAddress& address) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(64 << 20);  // a capture of three 2048 x 2048 frames fits
  if (IsUnix(address.target))
    return grpc::CreateCustomChannel(address.target, grpc::InsecureChannelCredentials(), args);
  if (address.tls_ca.empty() || address.tls_certificate.empty() || address.tls_key.empty())
    throw CommandError(kExitUsage, "--daemon " + address.target +
                                       " is TCP, which is mutual TLS only: give --tls-ca, "
                                       "--tls-cert and --tls-key");
  grpc::SslCredentialsOptions tls;
  tls.pem_root_certs = ReadPem(address.tls_ca, "--tls-ca");
  tls.pem_cert_chain = ReadPem(address.tls_certificate, "--tls-cert");
  tls.pem_private_key = ReadPem(address.tls_key, "--tls-key");
  return grpc::CreateCustomChannel(address.target, grpc::SslCredentials(tls), args);
}

std::unique_ptr<grpc::ClientContext> CallContext(const ServiceAddress& address) {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::milliseconds(static_cast<long>(address.timeout_s * 1000)));
  return context;
}

void CheckCall(const grpc::Status& status, const std::string& what, const ServiceAddress& address) {
  if (status.ok()) return;
  const std::string message = what + " at " + address.target + ": " + status.error_message();
  switch (status.error_code()) {
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::OUT_OF_RANGE:
      throw CommandError(kExitUsage, message);
    case grpc::StatusCode::NOT_FOUND:
      throw CommandError(kExitInput, message);
    case grpc::StatusCode::UNAVAILABLE:
      throw CommandError(kExitUnavailable, what + ": cannot reach " + address.target + " (" +
                                               status.error_message() + ")");
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      throw CommandError(kExitUnavailable, what + " at " + address.target +
                                               ": no answer within the deadline (" +
                                               status.error_message() + ")");
    case grpc::StatusCode::PERMISSION_DENIED:
    case grpc::StatusCode::UNAUTHENTICATED:
      throw CommandError(kExitRefused, message);
    default:
      throw CommandError(kExitServiceFailed, message);
  }
}

}  // namespace bsls::cli
