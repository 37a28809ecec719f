#include "daemon_connection.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "bsls/rpc/tls.h"

namespace bsls::cli {

namespace {

constexpr const char* kSystemSocket = "unix:/run/bsls/bslsd.sock";

void AddTlsOptions(CLI::App& command, ServiceAddress& address) {
  command.add_option("--tls-ca", address.tls_ca, "CA certificate (PEM) that signed the service's");
  command.add_option("--tls-cert", address.tls_certificate, "our client certificate (PEM)");
  command.add_option("--tls-key", address.tls_key, "its private key (PEM)");
  command.add_option("--timeout", address.timeout_s, "seconds each call may take")
      ->check(CLI::Range(0.1, 3600.0));
}

}  // namespace

rpc::TlsFiles TlsOf(const ServiceAddress& address) {
  return {address.tls_ca, address.tls_certificate, address.tls_key, "--tls-ca", "--tls-cert",
          "--tls-key"};
}

void AddDaemonOptions(CLI::App& command, ServiceAddress& address) {
  const char* from_env = std::getenv("BSLS_DAEMON");
  address.target = from_env != nullptr && *from_env != '\0' ? from_env : kSystemSocket;
  command.add_option("--daemon", address.target,
                     "the capture daemon: unix:PATH, or HOST:PORT with mutual TLS "
                     "(default $BSLS_DAEMON, else unix:/run/bsls/bslsd.sock)");
  AddTlsOptions(command, address);
}

void AddServerOptions(CLI::App& command, ServiceAddress& address) {
  const char* from_env = std::getenv("BSLS_SERVER");
  address.target = from_env != nullptr ? from_env : "";
  address.timeout_s = 300;
  command.add_option("--server", address.target,
                     "do the work on the processing service: unix:PATH, HOST:PORT (mutual TLS), "
                     "or several for round_robin: ipv4:H:P,H:P or dns:///NAME:PORT (default "
                     "$BSLS_SERVER, else here)");
  AddTlsOptions(command, address);
}

void CheckWork(const grpc::Status& status, const std::string& what, const ServiceAddress& address) {
  switch (status.error_code()) {
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::NOT_FOUND:
      throw CommandError(kExitInput, what + ": " + status.error_message());
    case grpc::StatusCode::FAILED_PRECONDITION:
      throw CommandError(kExitNotProcessed, what + ": " + status.error_message());
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      throw CommandError(kExitUnavailable,
                         what + ": " +
                             (address.target.empty() ? std::string("the processing service here")
                                                     : "every replica at " + address.target) +
                             " is busy (" + status.error_message() + ")");
    default:
      CheckCall(status, what, address);
  }
}

processing::ProgressCallback ProgressPrinter(bool quiet) {
  if (quiet) return {};
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  return [terminal, last = std::string()](const v1::Progress& p) mutable {
    if (p.stage() == last) return;
    last = p.stage();
    if (terminal)
      std::fprintf(stderr, "\r\033[Kbsls: %3.0f%% %s", 100.0 * p.fraction(), p.stage().c_str());
    else
      std::fprintf(stderr, "bsls: %3.0f%% %s\n", 100.0 * p.fraction(), p.stage().c_str());
    if (terminal && p.fraction() >= 0.95) std::fprintf(stderr, "\n");
  };
}

std::shared_ptr<grpc::Channel> OpenChannel(const ServiceAddress& address) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(64 << 20);  // a capture of three 2048 x 2048 frames fits
  if (rpc::IsUnixTarget(address.target))
    return grpc::CreateCustomChannel(address.target, grpc::InsecureChannelCredentials(), args);
  if (address.tls_ca.empty() || address.tls_certificate.empty() || address.tls_key.empty())
    throw CommandError(kExitUsage, "--daemon " + address.target +
                                       " is TCP, which is mutual TLS only: give --tls-ca, "
                                       "--tls-cert and --tls-key");
  try {
    return grpc::CreateCustomChannel(address.target,
                                     rpc::MutualTlsChannelCredentials(TlsOf(address)), args);
  } catch (const rpc::TlsFileError& e) {
    throw CommandError(kExitInput, e.what());
  }
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
