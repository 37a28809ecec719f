#include "bsls/rpc/tls_session.h"

#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include <algorithm>
#include <climits>

namespace bsls::rpc {
namespace {

constexpr std::size_t kMaxCommonNameBytes = 256;  // longer names are refused

// OpenSSL's reasons queued on this thread, oldest first, and the queue cleared.
std::string OpenSslErrors() {
  std::string text;
  while (const unsigned long code = ERR_get_error()) {
    char line[256];
    ERR_error_string_n(code, line, sizeof line);
    text += (text.empty() ? "" : "; ") + std::string(line);
  }
  return text.empty() ? "unknown reason" : text;
}

// A BIO reading `pem` (which must outlive it).
std::unique_ptr<BIO, decltype(&BIO_free)> MemoryBio(const std::string& pem) {
  return {BIO_new_mem_buf(pem.data(), static_cast<int>(pem.size())), BIO_free};
}

// Selects "h2" among the protocols the client offers (ALPN), or ends the
// handshake when it offers others only.
int SelectH2(SSL*, const unsigned char** out, unsigned char* out_length, const unsigned char* in,
             unsigned int in_length, void*) {
  static const unsigned char kH2[] = {2, 'h', '2'};
  unsigned char* selected = nullptr;
  if (SSL_select_next_proto(&selected, out_length, kH2, sizeof kH2, in, in_length) !=
      OPENSSL_NPN_NEGOTIATED)
    return SSL_TLSEXT_ERR_ALERT_FATAL;
  *out = selected;
  return SSL_TLSEXT_ERR_OK;
}

// The common name of `certificate`'s subject ("" when it has none or an
// unusable one).
std::string CommonName(X509* certificate) {
  const X509_NAME* subject = X509_get_subject_name(certificate);
  const int index = X509_NAME_get_index_by_NID(subject, NID_commonName, -1);
  if (index < 0) return "";
  unsigned char* text = nullptr;
  const int length =
      ASN1_STRING_to_UTF8(&text, X509_NAME_ENTRY_get_data(X509_NAME_get_entry(subject, index)));
  if (length < 0) return "";
  std::string name(reinterpret_cast<const char*>(text), static_cast<std::size_t>(length));
  OPENSSL_free(text);
  if (name.size() > kMaxCommonNameBytes || name.find('\0') != std::string::npos) return "";
  return name;
}

}  // namespace

std::shared_ptr<const TlsServerContext> TlsServerContext::Create(const TlsFiles& files) {
  const std::string ca = ReadPemFile(files.ca, files.ca_setting);
  const std::string chain = ReadPemFile(files.certificate, files.certificate_setting);
  const std::string key_pem = ReadPemFile(files.key, files.key_setting);
  ERR_clear_error();
  SSL_CTX* raw = SSL_CTX_new(TLS_server_method());
  if (raw == nullptr) throw TlsFileError("TLS: no context: " + OpenSslErrors());
  std::shared_ptr<const TlsServerContext> made(new TlsServerContext(raw));
  const auto fail = [](const std::string& setting, const std::string& path, const char* what) {
    throw TlsFileError(setting + " " + path + ": " + what + ": " + OpenSslErrors());
  };

  // Our certificate, then the rest of its chain.
  auto chain_bio = MemoryBio(chain);
  X509* leaf = PEM_read_bio_X509_AUX(chain_bio.get(), nullptr, nullptr, nullptr);
  if (leaf == nullptr || SSL_CTX_use_certificate(raw, leaf) != 1) {
    X509_free(leaf);
    fail(files.certificate_setting, files.certificate, "not a usable certificate");
  }
  X509_free(leaf);
  while (X509* link = PEM_read_bio_X509(chain_bio.get(), nullptr, nullptr, nullptr)) {
    if (SSL_CTX_add0_chain_cert(raw, link) != 1) {
      X509_free(link);
      fail(files.certificate_setting, files.certificate, "a chain certificate is not usable");
    }
  }
  ERR_clear_error();  // the end of the chain reads as an error

  auto key_bio = MemoryBio(key_pem);
  EVP_PKEY* key = PEM_read_bio_PrivateKey(key_bio.get(), nullptr, nullptr, nullptr);
  if (key == nullptr || SSL_CTX_use_PrivateKey(raw, key) != 1) {
    EVP_PKEY_free(key);
    fail(files.key_setting, files.key, "not a usable private key");
  }
  EVP_PKEY_free(key);
  if (SSL_CTX_check_private_key(raw) != 1)
    fail(files.key_setting, files.key, "does not match the certificate");

  // The CA (or CAs) the client certificates are verified against, also
  // named to clients in the handshake.
  auto ca_bio = MemoryBio(ca);
  int authorities = 0;
  while (X509* authority = PEM_read_bio_X509(ca_bio.get(), nullptr, nullptr, nullptr)) {
    const bool added = X509_STORE_add_cert(SSL_CTX_get_cert_store(raw), authority) == 1 &&
                       SSL_CTX_add_client_CA(raw, authority) == 1;
    X509_free(authority);
    if (!added) fail(files.ca_setting, files.ca, "a CA certificate is not usable");
    ++authorities;
  }
  ERR_clear_error();
  if (authorities == 0) fail(files.ca_setting, files.ca, "holds no certificate");

  SSL_CTX_set_min_proto_version(raw, TLS1_2_VERSION);
  SSL_CTX_set_options(raw, SSL_OP_NO_RENEGOTIATION | SSL_OP_IGNORE_UNEXPECTED_EOF |
                               SSL_OP_CIPHER_SERVER_PREFERENCE | SSL_OP_NO_TICKET);
  // Each connection verified whole: no sessions to resume.
  SSL_CTX_set_session_cache_mode(raw, SSL_SESS_CACHE_OFF);
  SSL_CTX_set_num_tickets(raw, 0);
  SSL_CTX_set_mode(raw, SSL_MODE_ENABLE_PARTIAL_WRITE | SSL_MODE_ACCEPT_MOVING_WRITE_BUFFER |
                            SSL_MODE_RELEASE_BUFFERS);
  SSL_CTX_set_verify(raw, SSL_VERIFY_PEER | SSL_VERIFY_FAIL_IF_NO_PEER_CERT, nullptr);
  SSL_CTX_set_alpn_select_cb(raw, SelectH2, nullptr);
  return made;
}

TlsServerContext::~TlsServerContext() { SSL_CTX_free(context_); }

TlsSession::TlsSession(const TlsServerContext& context, int fd) : ssl_(SSL_new(context.context_)) {
  if (ssl_ != nullptr) {
    SSL_set_fd(ssl_, fd);
    SSL_set_accept_state(ssl_);
  }
}

TlsSession::~TlsSession() { SSL_free(ssl_); }

TlsSession::Step TlsSession::Classify(int rc, const char* what) {
  switch (SSL_get_error(ssl_, rc)) {
    case SSL_ERROR_WANT_READ:
      return Step::kWantRead;
    case SSL_ERROR_WANT_WRITE:
      return Step::kWantWrite;
    case SSL_ERROR_ZERO_RETURN:
      return Step::kClosed;
    case SSL_ERROR_SYSCALL:
      error_ = std::string(what) + ": the connection failed";
      ERR_clear_error();
      return Step::kFailed;
    default:
      error_ = std::string(what) + ": " + OpenSslErrors();
      if (const long verify = SSL_get_verify_result(ssl_); verify != X509_V_OK)
        error_ +=
            " (client certificate: " + std::string(X509_verify_cert_error_string(verify)) + ")";
      return Step::kFailed;
  }
}

TlsSession::Step TlsSession::Handshake() {
  if (ssl_ == nullptr) {
    error_ = "TLS: no session could be made";
    return Step::kFailed;
  }
  ERR_clear_error();
  const int rc = SSL_do_handshake(ssl_);
  if (rc != 1) return Classify(rc, "TLS handshake");
  // SSL_VERIFY_FAIL_IF_NO_PEER_CERT made a certificate and its chain
  // necessary; what the application needs of it is its name.
  X509* certificate = SSL_get0_peer_certificate(ssl_);
  if (certificate == nullptr || SSL_get_verify_result(ssl_) != X509_V_OK) {
    error_ = "TLS handshake: no verified client certificate";
    return Step::kFailed;
  }
  common_name_ = CommonName(certificate);
  if (common_name_.empty()) {
    error_ = "TLS handshake: the client certificate has no usable common name";
    return Step::kFailed;
  }
  return Step::kDone;
}

TlsSession::Step TlsSession::Read(std::string* into, std::size_t room) {
  char buffer[16384];
  while (room > 0) {
    ERR_clear_error();
    const int n = SSL_read(ssl_, buffer, static_cast<int>(std::min(sizeof buffer, room)));
    if (n <= 0) return Classify(n, "TLS read");
    into->append(buffer, static_cast<std::size_t>(n));
    room -= static_cast<std::size_t>(n);
  }
  return Step::kDone;
}

TlsSession::Step TlsSession::Write(std::string* from, std::size_t count) {
  while (count > 0) {
    ERR_clear_error();
    const int n =
        SSL_write(ssl_, from->data(), static_cast<int>(std::min<std::size_t>(count, INT_MAX)));
    if (n <= 0) return Classify(n, "TLS write");
    from->erase(0, static_cast<std::size_t>(n));
    count -= static_cast<std::size_t>(n);
  }
  return Step::kDone;
}

void TlsSession::Close() {
  if (closed_ || ssl_ == nullptr || !SSL_is_init_finished(ssl_)) return;
  closed_ = true;
  ERR_clear_error();
  SSL_shutdown(ssl_);
  ERR_clear_error();
}

bool TlsSession::buffered() const { return ssl_ != nullptr && SSL_pending(ssl_) > 0; }

}  // namespace bsls::rpc
