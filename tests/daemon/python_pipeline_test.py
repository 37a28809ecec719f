#!/usr/bin/python3
"""The capture-to-mesh pipeline through the Python client, as a new user's
first run does it: bslsd (simulated framestore) hands the grab to a real
bsls-processd; the automation example (clients/python/examples/
scripted_session.py) grabs both sides, waits for the reconstruction and writes
the surface, the reports, the sealed record and the measurements to a folder.

    python_pipeline_test.py BSLSD BSLS_PROCESSD BSLS [unittest args]
"""
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
import unittest

from bsls_client import CaptureClient, CaptureError

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "support"))
from bslsd_harness import Bslsd, answers  # noqa: E402

BSLSD = PROCESSD = BSLS = None
EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "..", "clients", "python", "examples",
                       "scripted_session.py")


def run(*args):
    return subprocess.run(list(args), capture_output=True, text=True, timeout=600)


class PythonPipelineTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory(prefix="bsls_pipeline_")
        calibrations = {}
        for side, seed in (("left", "5"), ("right", "6")):
            session = os.path.join(cls.dir.name, side)
            r = run(BSLS, "simulate-calibration", "--side", side, "-o", session, "--noise", "2",
                    "--seed", seed, "--supersampling", "1")
            assert r.returncode == 0, r.stderr
            calibrations[side] = os.path.join(cls.dir.name, side + ".yaml")
            r = run(BSLS, "calibrate", os.path.join(session, "session.yaml"),
                    "-o", calibrations[side])
            assert r.returncode == 0, r.stderr
        cls.processd_socket = os.path.join(cls.dir.name, "processd.sock")
        cls.processd_log = open(os.path.join(cls.dir.name, "processd.log"), "w")
        cls.processd = subprocess.Popen(
            [PROCESSD, "--socket", cls.processd_socket, "--workers", "1", "--replica", "py-e2e",
             "--set", "scratch_dir=" + cls.dir.name], stdout=subprocess.DEVNULL,
            stderr=cls.processd_log)
        for _ in range(200):
            if os.path.exists(cls.processd_socket):
                break
            time.sleep(0.05)

        cls.daemon = Bslsd(BSLSD, answers, "  admin: [root]\n  others: admin\n",
                           prefix="bslsd_pipeline_",
                           extra=f"processing:\n  server: unix:{cls.processd_socket}\n"
                                 f"  calibration_left: {calibrations['left']}\n"
                                 f"  calibration_right: {calibrations['right']}\n")

    @classmethod
    def tearDownClass(cls):
        code = cls.daemon.stop()
        cls.processd.terminate()
        cls.processd.wait(60)
        cls.processd_log.close()
        cls.dir.cleanup()
        assert code == 0, f"bslsd exited with {code}"

    def test_scripted_session_writes_the_mesh_the_record_and_the_measurements(self):
        out = os.path.join(self.dir.name, "session")
        r = run("/usr/bin/python3", EXAMPLE, "--socket", self.daemon.socket, "--session", "e2e",
                "--patient", "P-42", "--out", out, "--processd", "unix:" + self.processd_socket)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr + self.daemon.log())
        for name in ("surface.ply", "left.ply", "right.ply", "report.json", "record.json",
                     "measurements.json", "measurements.txt"):
            self.assertTrue(os.path.getsize(os.path.join(out, name)) > 0, name)
        with open(os.path.join(out, "record.json")) as f:
            record = json.load(f)
        self.assertEqual(record["patient_reference"], "P-42")
        self.assertEqual(record["replica"], "py-e2e")
        for name, sha256 in record["files"].items():
            with open(os.path.join(out, name), "rb") as f:
                self.assertEqual(hashlib.sha256(f.read()).hexdigest(), sha256, name)
        with open(os.path.join(out, "measurements.json")) as f:
            measured = json.load(f)
        self.assertEqual(len(measured["heights"]), 2)
        self.assertGreater(measured["distances"][0]["geodesic_mm"]["value"], 45.0)
        with open(os.path.join(out, "report.json")) as f:
            self.assertEqual(json.load(f)["join"]["method"], "shared-frame")

        # The daemon kept it with the capture: the same record, its hash in the status.
        with CaptureClient.unix(self.daemon.socket) as bsls:
            captures = list(bsls.captures(session_id="e2e"))
            self.assertEqual(len(captures), 1)
            capture = captures[0]
            self.assertEqual(capture.processing.state, "done")
            stored = bsls.results(capture.capture_id, "record.json")["record.json"]
            self.assertEqual(hashlib.sha256(stored).hexdigest(), capture.processing.record_sha256)
            with self.assertRaises(CaptureError) as missing:
                bsls.results(capture.capture_id, "no-such-file.bin")
            self.assertEqual(missing.exception.code.name, "NOT_FOUND")


if __name__ == "__main__":
    BSLSD, PROCESSD, BSLS = sys.argv[1:4]
    del sys.argv[1:4]
    unittest.main(verbosity=2)
