// A mutual-TLS client for the tests that speak raw HTTP/2 (header only;
// OpenSSL): Open() makes a TLS connection to a loopback port with a client
// certificate and ALPN "h2", and returns the plaintext end of a socket pair
// that a thread relays through it, so that the raw-frame helpers
// (bsls/testing/http2_flood.h) work on a TLS listener as on a Unix socket.
// A tunnel ends when either side closes; the destructor ends them all.
//
// Thread-safety: Open may be called from several threads at once (the
// floods open their connections from one thread each).
#ifndef BSLS_TESTING_TLS_TUNNEL_H_
#define BSLS_TESTING_TLS_TUNNEL_H_

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bsls/testing/certificates.h"

namespace bsls::testing {

class TlsTunnels {
 public:
  // Tunnels presenting `client` (its key and certificate; none when empty)
  // and trusting `server_ca`.
  TlsTunnels(const PemFiles& client, const std::filesystem::path& server_ca)
      : context_(SSL_CTX_new(TLS_client_method()), SSL_CTX_free) {
    SSL_CTX* context = context_.get();
    ok_ = context != nullptr &&
          SSL_CTX_load_verify_locations(context, server_ca.c_str(), nullptr) == 1;
    if (ok_ && !client.certificate.empty())
      ok_ = SSL_CTX_use_certificate_chain_file(context, client.certificate.c_str()) == 1 &&
            SSL_CTX_use_PrivateKey_file(context, client.key.c_str(), SSL_FILETYPE_PEM) == 1;
    if (ok_) {
      static const unsigned char kH2[] = {2, 'h', '2'};
      SSL_CTX_set_alpn_protos(context, kH2, sizeof kH2);
      SSL_CTX_set_verify(context, SSL_VERIFY_PEER, nullptr);
    }
  }
  ~TlsTunnels() {
    stopping_ = true;
    const std::lock_guard<std::mutex> lock(threads_mutex_);
    for (std::thread& thread : threads_) thread.join();
  }
  TlsTunnels(const TlsTunnels&) = delete;
  TlsTunnels& operator=(const TlsTunnels&) = delete;

  // Whether the certificate files could be used.
  bool ok() const { return ok_; }

  // The plaintext end of a new tunnel to 127.0.0.1:`port`; -1 when the
  // connection or its handshake failed (the server refused the client).
  int Open(int port) {
    if (!ok_) return -1;
    const int tcp = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (tcp < 0 || ::connect(tcp, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      if (tcp >= 0) ::close(tcp);
      return -1;
    }
    const int on = 1;
    ::setsockopt(tcp, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    SSL* ssl = SSL_new(context_.get());
    SSL_set_fd(ssl, tcp);
    SSL_set_tlsext_host_name(ssl, "localhost");
    SSL_set1_host(ssl, "localhost");
    // TLS 1.3 reports a refused client certificate only at the first read.
    int plain[2];
    if (SSL_connect(ssl) != 1 || !Accepted(ssl) ||
        ::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, plain) != 0) {
      SSL_free(ssl);
      ::close(tcp);
      ERR_clear_error();
      return -1;
    }
    // From here on the relay waits at most this long in any one call.
    const timeval slice{0, 20000};
    ::setsockopt(tcp, SOL_SOCKET, SO_RCVTIMEO, &slice, sizeof slice);
    ::setsockopt(tcp, SOL_SOCKET, SO_SNDTIMEO, &slice, sizeof slice);
    const std::lock_guard<std::mutex> lock(threads_mutex_);
    threads_.emplace_back([this, ssl, tcp, inner = plain[0]] { Relay(ssl, tcp, inner); });
    return plain[1];
  }

 private:
  // True when the server did not close the connection right after the
  // handshake (the way TLS 1.3 refuses a client certificate).
  static bool Accepted(SSL* ssl) {
    pollfd fd{SSL_get_fd(ssl), POLLIN, 0};
    if (::poll(&fd, 1, 200) <= 0) return true;  // nothing said: accepted
    char byte;
    return SSL_peek(ssl, &byte, 1) > 0;  // data (the server's SETTINGS) or an alert
  }

  // Relays between `ssl` (on `tcp`) and the plaintext socket `inner` until
  // either ends or the tunnels stop.
  void Relay(SSL* ssl, int tcp, int inner) {
    std::string out;  // read from `inner`, not yet written to TLS
    char buffer[16384];
    bool open = true;
    while (open && !stopping_) {
      pollfd fds[2] = {{inner, static_cast<short>(out.empty() ? POLLIN : 0), 0}, {tcp, POLLIN, 0}};
      ::poll(fds, 2, 20);
      if ((fds[0].revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
        const ssize_t n = ::recv(inner, buffer, sizeof buffer, 0);
        if (n <= 0) break;
        out.assign(buffer, static_cast<std::size_t>(n));
      }
      while (!out.empty() && !stopping_) {
        const int n = SSL_write(ssl, out.data(), static_cast<int>(out.size()));
        if (n > 0) {
          out.erase(0, static_cast<std::size_t>(n));
          continue;
        }
        const int error = SSL_get_error(ssl, n);
        if (error != SSL_ERROR_WANT_WRITE && error != SSL_ERROR_WANT_READ) open = false;
        break;
      }
      while (open && ((fds[1].revents != 0) || SSL_pending(ssl) > 0)) {
        fds[1].revents = 0;
        const int n = SSL_read(ssl, buffer, sizeof buffer);
        if (n <= 0) {
          const int error = SSL_get_error(ssl, n);
          open = error == SSL_ERROR_WANT_READ || error == SSL_ERROR_WANT_WRITE;
          break;
        }
        if (::send(inner, buffer, static_cast<std::size_t>(n), MSG_NOSIGNAL) != n) open = false;
      }
      ERR_clear_error();
    }
    SSL_free(ssl);
    ::close(tcp);
    ::close(inner);
  }

  std::unique_ptr<SSL_CTX, decltype(&SSL_CTX_free)> context_;
  bool ok_ = false;
  std::atomic<bool> stopping_{false};
  std::mutex threads_mutex_;  // guards threads_
  std::vector<std::thread> threads_;
};

}  // namespace bsls::testing

#endif  // BSLS_TESTING_TLS_TUNNEL_H_
