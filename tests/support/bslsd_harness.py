"""bslsd for the Python test drivers: a throw-away CA with server and client
certificates (the openssl command; the C++ tests have
tests/support/include/bsls/testing/certificates.h), and a daemon on the
simulated framestore listening on a temporary Unix socket and on mutual-TLS
loopback TCP."""
import os
import socket
import subprocess
import tempfile
import time


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


def answers(socket):
    """True when a daemon answers GetStatus on `socket` (the Bslsd ready probe
    of the Python client tests)."""
    from bsls_client import CaptureClient, CaptureError
    try:
        with CaptureClient.unix(socket, timeout=5) as client:
            client.status()
        return True
    except CaptureError:
        return False


class ServiceProcess:
    """A service started by a test with its output in `self._log` (an open
    file) and its process in `self.process`: what it wrote, and SIGTERM."""

    def log(self):
        """What the service wrote so far."""
        with open(self._log.name) as f:
            return f.read()

    def stop(self):
        """SIGTERM; the exit code (0 when it drained cleanly)."""
        self.process.terminate()
        code = self.process.wait(60)
        self._log.close()
        return code


class Bslsd(ServiceProcess):
    """A running bslsd in a fresh temporary folder: `socket`, `port`, `pki(name)`.

    `roles` is the YAML under `roles:` (two-space indented lines);
    `certificates` the client certificate names to make; `extra` more
    top-level YAML (e.g. a processing: section). `ready(socket)` is called
    until it returns True (the caller's own client probing the socket)."""

    def __init__(self, bslsd, ready, roles, certificates=("station",), prefix="bslsd_",
                 extra=""):
        self.dir = tempfile.mkdtemp(prefix=prefix)
        self.socket = os.path.join(self.dir, "bslsd.sock")
        self.pki = make_pki(self.dir, clients=certificates)
        self.port = free_port()
        config = os.path.join(self.dir, "bslsd.yaml")
        with open(config, "w") as out:
            out.write(f"store:\n  root: {self.dir}/store\n  reserve_mib: 16\n"
                      f"listen:\n  unix_socket: {self.socket}\n"
                      f"  tcp: 127.0.0.1:{self.port}\n"
                      f"  tls_certificate: {self.pki('server.pem')}\n"
                      f"  tls_key: {self.pki('server.key')}\n"
                      f"  tls_client_ca: {self.pki('ca.pem')}\n"
                      f"roles:\n{roles}"
                      "framestore:\n  simulated_breathing_mm: 0\n"
                      "slides:\n  backend: simulated\nlog_level: warn\n"
                      # The test's own account: started as root, bslsd would become `bsls`.
                      f"user: \"{os.geteuid()}:{os.getegid()}\"\n" + extra)
        self._log = open(os.path.join(self.dir, "bslsd.log"), "w")
        self.process = subprocess.Popen([bslsd, "--config", config], stdout=self._log,
                                        stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 120
        while not ready(self.socket):
            if time.monotonic() > deadline or self.process.poll() is not None:
                raise RuntimeError("bslsd did not start: " + self.log())
            time.sleep(0.1)

