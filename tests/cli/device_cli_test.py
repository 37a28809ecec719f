#!/usr/bin/python3
"""The capture daemon's commands of `bsls` as an operator or a script runs
them, against a real bslsd on the simulated framestore: status, camera, gain,
slide, grab, captures, preview; over the Unix socket and over mutual-TLS TCP;
and the exit codes of command.h for what goes wrong.

Usage: device_cli_test.py BSLS BSLSD [unittest args]
"""
import json
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "support"))
from bslsd_harness import Bslsd  # noqa: E402

BSLS = None
BSLSD = None

EXIT_OK, EXIT_USAGE, EXIT_INPUT, EXIT_UNAVAILABLE, EXIT_REFUSED = 0, 2, 3, 5, 6


class DeviceCliTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Bslsd(BSLSD, lambda socket: cls.bsls("status", daemon="unix:" + socket)
                           .returncode == EXIT_OK,
                           "  admin: [root]\n  certificates:\n    station: operator\n",
                           prefix="bsls_device_cli_")
        cls.dir, cls.socket, cls.port = cls.daemon.dir, cls.daemon.socket, cls.daemon.port
        cls.pki = staticmethod(cls.daemon.pki)

    @classmethod
    def tearDownClass(cls):
        code = cls.daemon.stop()
        assert code == 0, f"bslsd exited with {code}"

    @classmethod
    def bsls(cls, *args, daemon=None):
        return subprocess.run([BSLS, *args, "--daemon", daemon or "unix:" + cls.daemon.socket,
                               "--timeout", "60"],
                              capture_output=True, text=True, timeout=180)

    def ok(self, *args, **kwargs):
        result = self.bsls(*args, **kwargs)
        self.assertEqual(result.returncode, EXIT_OK, result.stderr)
        return result

    def test_status_names_the_device_and_the_callers_role(self):
        out = self.ok("status").stdout
        self.assertIn("simulated", out)
        self.assertIn("admin", out)
        status = json.loads(self.ok("status", "--json").stdout)
        self.assertEqual(status["backend"], "simulated")
        self.assertEqual(status["width"], 512)

    def test_slide_focus_and_lamp_reach_the_controller(self):
        state = json.loads(self.ok("slide", "reference", "--lamp", "on", "--json").stdout)
        self.assertEqual(state["slide"], 1)
        self.assertTrue(state["in_place"])
        self.assertTrue(state["lamp_on"])
        state = json.loads(self.ok("slide", "3", "--focus", "12", "--json").stdout)
        self.assertEqual(state["slide"], 3)
        self.assertEqual(state["focus_position"], 12)
        self.assertIn("slide 3 (right pattern), in place", self.ok("slide").stdout)

    def test_camera_and_gain(self):
        status = json.loads(self.ok("camera", "right", "--json").stdout)
        self.assertEqual(status["selected_camera"], "CAMERA_RIGHT")
        status = json.loads(self.ok("gain", "150", "--json").stdout)
        self.assertEqual(status["gain"], 150)
        result = self.bsls("gain", "100000")
        self.assertEqual(result.returncode, EXIT_USAGE, result.stderr)
        self.assertIn("gain 100000", result.stderr)
        self.ok("gain", str(status["gain_range"]["nominal"]))
        self.ok("camera", "left")

    def test_preview_needs_a_folder_or_a_display(self):
        r = self.bsls("preview", "--frames", "2")
        self.assertEqual(r.returncode, 2, r.stderr)
        env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
        r = subprocess.run([BSLS, "preview", "--show", "--frames", "2", "--daemon",
                            "unix:" + self.daemon.socket], capture_output=True, text=True,
                           timeout=60, env=env)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("no display", r.stderr)

    def test_grab_stores_the_frames_and_captures_finds_them(self):
        out = os.path.join(self.dir, "grab")
        capture = json.loads(self.ok("grab", "--side", "both", "--session", "cli-1",
                                     "--patient", "P-7", "-o", out, "--json").stdout)
        cid = capture["capture_id"]
        self.assertEqual(len(cid), 32)
        self.assertEqual(capture["session_id"], "cli-1")
        self.assertEqual([f["camera"] for f in capture["frames"]], ["CAMERA_LEFT", "CAMERA_RIGHT"])
        for side in ("left", "right"):
            self.assertGreater(os.path.getsize(os.path.join(out, f"{cid}_{side}.png")), 1000)
        listed = [json.loads(line) for line in
                  self.ok("captures", "list", "--session", "cli-1", "--json").stdout.splitlines()]
        self.assertEqual([c["capture_id"] for c in listed], [cid])
        # No processing service is configured: nothing to fetch, and it says so.
        shown = self.ok("captures", "get", cid).stdout
        self.assertIn("processing: not configured", shown)
        r = self.bsls("captures", "results", cid, "-o", os.path.join(self.dir, "results"))
        self.assertEqual(r.returncode, 3, r.stderr)
        self.assertIn("no stored results", r.stderr)
        again = os.path.join(self.dir, "again")
        self.ok("captures", "get", cid, "-o", again)
        with open(os.path.join(out, f"{cid}_left.png"), "rb") as a, \
                open(os.path.join(again, f"{cid}_left.png"), "rb") as b:
            self.assertEqual(a.read(), b.read())
        self.ok("captures", "delete", cid)
        result = self.bsls("captures", "get", cid)
        self.assertEqual(result.returncode, EXIT_INPUT, result.stderr)
        self.assertIn(cid, result.stderr)

    def test_preview_writes_frames(self):
        out = os.path.join(self.dir, "preview")
        report = json.loads(self.ok("preview", "--camera", "left", "--frames", "5", "-o", out,
                                    "--json").stdout)
        self.assertEqual(report["frames"], 5)
        self.assertEqual(sorted(os.listdir(out)), [f"preview_{i:05d}.png" for i in range(5)])

    def test_tcp_with_a_client_certificate(self):
        target = f"127.0.0.1:{self.port}"
        tls = ["--tls-ca", self.pki("ca.pem"), "--tls-cert", self.pki("station.pem"),
               "--tls-key", self.pki("station.key")]
        status = json.loads(self.ok("status", "--json", *tls, daemon=target).stdout)
        self.assertEqual(status["caller_role"], "operator")
        capture = json.loads(self.ok("grab", "--side", "left", "--json", *tls,
                                     daemon=target).stdout)
        self.assertEqual(capture["requested_by"], "station")
        # The operator may not delete (admin only).
        result = self.bsls("captures", "delete", capture["capture_id"], *tls, daemon=target)
        self.assertEqual(result.returncode, EXIT_REFUSED, result.stderr)
        # TCP without the TLS files is refused by the tool itself.
        result = self.bsls("status", daemon=target)
        self.assertEqual(result.returncode, EXIT_USAGE, result.stderr)
        self.assertIn("mutual TLS", result.stderr)

    def test_what_goes_wrong_has_its_exit_code(self):
        result = self.bsls("slide", "7")
        self.assertEqual(result.returncode, EXIT_USAGE)
        result = self.bsls("captures", "get", "not-an-id")
        self.assertEqual(result.returncode, EXIT_USAGE, result.stderr)
        self.assertIn("capture id", result.stderr)
        result = self.bsls("status", daemon="unix:" + os.path.join(self.dir, "nobody.sock"))
        self.assertEqual(result.returncode, EXIT_UNAVAILABLE, result.stderr)
        self.assertIn("cannot reach", result.stderr)
        self.assertEqual(result.stderr.count("\n"), 1, result.stderr)


if __name__ == "__main__":
    BSLSD = sys.argv.pop(2)
    BSLS = sys.argv.pop(1)
    unittest.main(verbosity=2)
