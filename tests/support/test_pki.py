"""A throw-away CA with server and client certificates for the mutual-TLS
tests of the Python test drivers, made with the openssl command (the C++
tests have tests/support/include/bsls/testing/certificates.h)."""
import os
import socket
import subprocess


def _openssl(*args):
    subprocess.run(["openssl", *args], check=True, capture_output=True)


def make_pki(folder, clients=("station",)):
    """Makes ca.pem, server.pem/key (localhost, 127.0.0.1) and NAME.pem/key for
    each client name in `folder`; returns a function from a file name to its path."""
    def path(name):
        return os.path.join(folder, name)
    _openssl("req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1",
             "-nodes", "-days", "2", "-subj", "/CN=test CA", "-keyout", path("ca.key"),
             "-out", path("ca.pem"))
    names = [("server", "subjectAltName=DNS:localhost,IP:127.0.0.1")]
    names += [(name, "extendedKeyUsage=clientAuth") for name in clients]
    for name, ext in names:
        with open(path(name + ".ext"), "w") as out:
            out.write(ext + "\n")
        _openssl("req", "-new", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1",
                 "-nodes", "-subj", "/CN=" + name, "-keyout", path(name + ".key"),
                 "-out", path(name + ".csr"))
        _openssl("x509", "-req", "-days", "2", "-in", path(name + ".csr"), "-CA", path("ca.pem"),
                 "-CAkey", path("ca.key"), "-CAcreateserial", "-extfile", path(name + ".ext"),
                 "-out", path(name + ".pem"))
    return path


def free_port():
    """A loopback TCP port nothing listens on right now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]
