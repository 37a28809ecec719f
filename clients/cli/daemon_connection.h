// How `bsls` reaches a running service (the capture daemon bslsd, the
// processing service bsls-processd): the address and TLS options every
// remote subcommand shares, the channel, the deadline of each call, and gRPC
// statuses mapped to the tool's exit codes.
#ifndef BSLS_CLIENTS_CLI_DAEMON_CONNECTION_H_
#define BSLS_CLIENTS_CLI_DAEMON_CONNECTION_H_

#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <memory>
#include <string>

#include "bsls/processing/processing_client.h"
#include "bsls/rpc/tls.h"
#include "command.h"

namespace bsls::cli {

// Where a service is and how to prove who we are to it.
struct ServiceAddress {
  // "unix:/run/bsls/bslsd.sock" (local, the caller's uid is its identity) or
  // "host:port" (mutual TLS: the three files below are required).
  std::string target;
  std::string tls_ca;           // the CA that signed the service's certificate
  std::string tls_certificate;  // our client certificate
  std::string tls_key;          // its private key
  double timeout_s = 30;        // the deadline of each call
};

// The TLS files `address` names, each named by its option in errors.
rpc::TlsFiles TlsOf(const ServiceAddress& address);

// Adds --daemon, --tls-ca, --tls-cert, --tls-key and --timeout to `command`;
// the daemon's address defaults to $BSLS_DAEMON, else the system socket.
void AddDaemonOptions(CLI::App& command, ServiceAddress& address);

// Adds --server (default $BSLS_SERVER; none: the service runs in this
// process, processing_route.h), the
// TLS options and --timeout to a command that can run on the processing
// service. --server takes one address or several for round_robin
// ("ipv4:127.0.0.1:7001,127.0.0.1:7002", "dns:///processd:7000").
void AddServerOptions(CLI::App& command, ServiceAddress& address);

// Throws the CommandError that the status of a processing call means: bad
// input (exit 3), not processed (1), busy or unreachable (5), refused (6),
// failed (7); returns when it is OK.
void CheckWork(const grpc::Status& status, const std::string& what, const ServiceAddress& address);

// Prints work progress on stderr ("\r" updates on a terminal, a line per
// stage otherwise); `quiet` prints nothing.
processing::ProgressCallback ProgressPrinter(bool quiet);

// A channel to the service; CommandError (exit 2) when TCP is asked for
// without the TLS files, (exit 3) when a TLS file cannot be read.
std::shared_ptr<grpc::Channel> OpenChannel(const ServiceAddress& address);

// A client context whose deadline is the address's timeout from now.
std::unique_ptr<grpc::ClientContext> CallContext(const ServiceAddress& address);

// Throws the CommandError that `status` of `what` (e.g. "SetSlide") means
// for a script; returns when it is OK.
void CheckCall(const grpc::Status& status, const std::string& what, const ServiceAddress& address);

}  // namespace bsls::cli

#endif  // BSLS_CLIENTS_CLI_DAEMON_CONNECTION_H_
