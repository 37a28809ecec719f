// Mutual TLS ended by the services themselves (OpenSSL), not by gRPC, so
// that the HTTP/2 frames inside can be counted by rpc::Http2Guard before
// gRPC reads them: a caller holding a certificate of the clinic's CA must
// not be able to flood a service with new streams, resets or pings that
// gRPC would take unbounded memory for (issue 26). The terms are the ones
// gRPC's own TLS gave: TLS 1.2 or later, a client certificate required and
// verified against the configured CA, ALPN "h2" (gRPC clients refuse a
// server that does not select it); a caller's identity is its
// certificate's common name.
//
// Thread-safety: a TlsServerContext is immutable once made and may be
// shared; a TlsSession is used by one thread at a time.
#ifndef BSLS_RPC_TLS_SESSION_H_
#define BSLS_RPC_TLS_SESSION_H_

#include <cstddef>
#include <memory>
#include <string>

#include "bsls/rpc/tls.h"

struct ssl_ctx_st;
struct ssl_st;

namespace bsls::rpc {

// The server's certificate and key, and the CA its clients' certificates
// must be signed by.
class TlsServerContext {
 public:
  // Loads and checks files (certificate chain, matching private key, CA);
  // throws TlsFileError naming the setting, the file and the reason.
  static std::shared_ptr<const TlsServerContext> Create(const TlsFiles& files);
  ~TlsServerContext();
  TlsServerContext(const TlsServerContext&) = delete;
  TlsServerContext& operator=(const TlsServerContext&) = delete;

 private:
  friend class TlsSession;
  explicit TlsServerContext(ssl_ctx_st* context) : context_(context) {}
  ssl_ctx_st* context_;
};

// The server end of one TLS connection on a non-blocking socket.
class TlsSession {
 public:
  // What a step did: finished, waits for the socket to be readable or
  // writable, met the peer's orderly end, or failed (see error()).
  enum class Step { kDone, kWantRead, kWantWrite, kClosed, kFailed };

  // A session on `fd` (not owned; it must outlive the session).
  TlsSession(const TlsServerContext& context, int fd);
  ~TlsSession();
  TlsSession(const TlsSession&) = delete;
  TlsSession& operator=(const TlsSession&) = delete;

  // Moves the handshake on; kDone once it is complete and the client's
  // certificate verified (common_name() then holds its name).
  Step Handshake();
  // Appends up to `room` decrypted bytes to `*into` (kDone when some or
  // none were there to read without waiting: see buffered()).
  Step Read(std::string* into, std::size_t room);
  // Encrypts and sends the first `count` bytes of `*from`, erasing what
  // went from its front.
  Step Write(std::string* from, std::size_t count);
  // Sends the close_notify alert, once, without waiting for an answer.
  void Close();

  // Whether decrypted bytes wait inside the session (a poll on the socket
  // would not wake for them).
  bool buffered() const;
  // The verified client certificate's common name ("" before the handshake).
  const std::string& common_name() const { return common_name_; }
  // Why the last step failed.
  const std::string& error() const { return error_; }

 private:
  // The step an OpenSSL call's result `rc` means (error() set on failure).
  Step Classify(int rc, const char* what);

  ssl_st* ssl_;
  std::string common_name_;
  std::string error_;
  bool closed_ = false;
};

}  // namespace bsls::rpc

#endif  // BSLS_RPC_TLS_SESSION_H_
