// bsls-processd assembled: the processing service on a gRPC server with its
// size caps, the health service, and the listeners of the configuration (a
// Unix socket for this machine, accepted by rpc::UnixAcceptor within the
// connection limits and relayed through rpc::Http2Guard; TCP with mutual
// TLS or plain on loopback).
// main() wraps it with signals and systemd notification; the tests and the
// benchmark start replicas in-process through the same class.
#ifndef BSLS_PROCESSD_SERVER_H_
#define BSLS_PROCESSD_SERVER_H_

#include <grpcpp/grpcpp.h>
#include <sys/types.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "bsls/processing/processing_service.h"
#include "bsls/rpc/tcp_acceptor.h"
#include "bsls/rpc/unix_acceptor.h"
#include "config.h"

namespace bsls::processd {

class Server {
 public:
  // Starts serving `config` (checked first). Throws ConfigError naming the
  // key, rpc::TlsFileError for an unusable TLS file, std::runtime_error when
  // a listener cannot be bound or the Unix socket is served by another live
  // instance (a stale socket file left by a dead one is replaced).
  static std::unique_ptr<Server> Start(const Config& config, const std::string& software_version);
  // Drains (see Drain) if not done yet.
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Refuses new work, stops work under way at its next stage and gives
  // calls `drain_timeout_ms` to end; then the server is down.
  void Drain();
  // The TCP port bound (0 without TCP).
  int tcp_port() const { return tcp_port_; }
  // The service, for tests.
  processing::ProcessingService& service() { return *service_; }

 private:
  Server() = default;

  Config config_;
  std::unique_ptr<processing::ProcessingService> service_;
  std::unique_ptr<grpc::Server> server_;
  // The Unix socket: its connections are accepted here (within the
  // listen.max_connections* limits) and handed to server_ through its
  // rpc::Http2Guard (new streams, resets and pings at a bounded rate).
  std::unique_ptr<rpc::UnixAcceptor> acceptor_;
  // TCP: its connections are accepted here (within the
  // listen.max_tcp_connections* limits) and handed to server_.
  rpc::TcpListener tcp_;
  int tcp_port_ = 0;
  bool drained_ = false;
};

}  // namespace bsls::processd

#endif  // BSLS_PROCESSD_SERVER_H_
