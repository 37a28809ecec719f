// A throw-away public-key infrastructure for the tests of mutual TLS: a CA,
// a server certificate for localhost/127.0.0.1 and client certificates, made
// with the openssl command (Debian's openssl package) in a test directory.
// Header only: the daemon's and the processing service's tests share it.
#ifndef BSLS_TESTING_CERTIFICATES_H_
#define BSLS_TESTING_CERTIFICATES_H_

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace bsls::testing {

// The PEM files of one key pair: key, certificate, and the CA that signed it.
struct PemFiles {
  std::filesystem::path key;
  std::filesystem::path certificate;
  std::filesystem::path ca;
};

// Reads a whole file (a PEM) into a string; empty when it cannot be read.
inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class TestPki {
 public:
  // A new CA named `name` in `dir` (created). ok() is false when openssl failed.
  TestPki(std::filesystem::path dir, const std::string& name) : dir_(std::move(dir)), name_(name) {
    std::filesystem::create_directories(dir_);
    ok_ =
        Run("openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2"
            " -subj '/CN=" +
            name + " test CA' -keyout " + Path("ca.key") + " -out " + Path("ca.pem"));
  }

  bool ok() const { return ok_; }
  std::filesystem::path ca() const { return dir_ / (name_ + "-ca.pem"); }

  // A certificate for `common_name`, signed by this CA; a server certificate
  // also names localhost and 127.0.0.1.
  PemFiles Issue(const std::string& common_name, bool server = false) {
    const std::string base = name_ + "-" + common_name;
    const std::string ext = (dir_ / (base + ".ext")).string();
    {
      std::ofstream out(ext);
      out << (server ? "subjectAltName=DNS:localhost,IP:127.0.0.1\nextendedKeyUsage=serverAuth\n"
                     : "extendedKeyUsage=clientAuth\n");
    }
    const std::string key = (dir_ / (base + ".key")).string();
    const std::string csr = (dir_ / (base + ".csr")).string();
    const std::string pem = (dir_ / (base + ".pem")).string();
    ok_ =
        ok_ &&
        Run("openssl req -new -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -subj '/CN=" +
            common_name + "' -keyout " + key + " -out " + csr) &&
        Run("openssl x509 -req -days 2 -in " + csr + " -CA " + Path("ca.pem") + " -CAkey " +
            Path("ca.key") + " -CAcreateserial -extfile " + ext + " -out " + pem);
    return {key, pem, ca()};
  }

 private:
  std::string Path(const std::string& leaf) const { return (dir_ / (name_ + "-" + leaf)).string(); }
  static bool Run(const std::string& command) {
    return std::system((command + " >/dev/null 2>&1").c_str()) == 0;
  }

  std::filesystem::path dir_;
  std::string name_;
  bool ok_ = false;
};

}  // namespace bsls::testing

#endif  // BSLS_TESTING_CERTIFICATES_H_
