#!/usr/bin/python3
"""bslsd driven through the Python client (clients/python/bsls_client), as an
automation script drives it: slides, grabs, captures, previews, events, and
the statuses of bad input.

    python_client_test.py BSLSD [unittest args]
"""
import os
import sys
import threading
import time
import unittest

import grpc

from bsls_client import CaptureClient, CaptureError

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "support"))
from bslsd_harness import Bslsd, answers  # noqa: E402

BSLSD = None


class DaemonTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Bslsd(BSLSD, answers,
                           "  admin: [root]\n  others: admin\n"
                           "  certificates:\n    analyst: viewer\n",
                           certificates=("analyst",), prefix="bslsd_python_")
        cls.socket, cls.port = cls.daemon.socket, cls.daemon.port
        cls.pki = staticmethod(cls.daemon.pki)
        cls.client = CaptureClient.unix(cls.socket, timeout=60)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        code = cls.daemon.stop()
        assert code == 0, f"bslsd exited with {code}"

    def test_scripted_session_stores_every_grab_with_its_slide(self):
        events = []
        listener = threading.Thread(
            target=lambda: events.extend(CaptureClient.unix(self.socket).events(timeout=20)))
        listener.start()
        time.sleep(0.5)
        taken = []
        for slide, side in ((1, "both"), (2, "left"), (3, "right")):
            state = self.client.set_slide(slide)
            self.assertEqual(state.slide, slide)
            self.assertTrue(state.in_place)
            capture = self.client.grab(side, session_id="py-session", patient_reference="P-7",
                                       include_frames=True)
            self.assertEqual(capture.slide, slide)
            self.assertEqual(len(capture.frames), 2 if side == "both" else 1)
            for frame in capture.frames:
                self.assertEqual(frame.image.shape, (512, 512))
                self.assertTrue(frame.verify())
            taken.append(capture.capture_id)
        listed = [c.capture_id for c in self.client.captures(session_id="py-session")]
        self.assertEqual(sorted(listed), sorted(taken))
        again = self.client.capture(taken[0])
        self.assertTrue(all(frame.verify() for frame in again.frames))
        listener.join()
        stored = {e.capture_stored.capture_id for e in events if e.HasField("capture_stored")}
        self.assertTrue(set(taken) <= stored)
        self.assertTrue(any(e.HasField("slide_changed") for e in events))

    def test_preview_delivers_live_frames(self):
        frames = list(self.client.preview(5))
        self.assertEqual(len(frames), 5)
        self.assertTrue(all(f.image is not None and f.image.shape == (512, 512) for f in frames))

    def test_bad_input_names_the_field_and_the_daemon_keeps_serving(self):
        with self.assertRaises(CaptureError) as raised:
            self.client.set_gain(100000)
        self.assertEqual(raised.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("gain 100000", raised.exception.details)
        with self.assertRaises(CaptureError) as raised:
            self.client.capture("f" * 32)
        self.assertEqual(raised.exception.code, grpc.StatusCode.NOT_FOUND)
        with self.assertRaises(CaptureError) as raised:
            self.client.grab("sideways")
        self.assertEqual(raised.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        with self.assertRaises(CaptureError) as raised:
            self.client.set_slide(0)
        self.assertEqual(raised.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertEqual(self.client.status().backend, "simulated")

    def test_delete_removes_a_capture(self):
        capture = self.client.grab("left", session_id="py-delete")
        self.client.delete(capture.capture_id)
        with self.assertRaises(CaptureError) as raised:
            self.client.capture(capture.capture_id)
        self.assertEqual(raised.exception.code, grpc.StatusCode.NOT_FOUND)

    def test_remote_analyst_over_mutual_tls_reads_but_may_not_grab(self):
        taken = self.client.grab("left", session_id="py-remote", include_frames=True)

        def read(name):
            with open(self.pki(name), "rb") as f:
                return f.read()
        with CaptureClient.tcp(f"127.0.0.1:{self.port}", read("ca.pem"), read("analyst.pem"),
                               read("analyst.key"), timeout=30) as remote:
            self.assertEqual(remote.status().caller_role, "viewer")
            fetched = remote.capture(taken.capture_id)
            self.assertTrue(all(frame.verify() for frame in fetched.frames))
            self.assertEqual(fetched.frames[0].sha256, taken.frames[0].sha256)
            with self.assertRaises(CaptureError) as raised:
                remote.grab("left")
            self.assertEqual(raised.exception.code, grpc.StatusCode.PERMISSION_DENIED)
        # Without a client certificate the handshake never completes.
        anonymous = CaptureClient(grpc.secure_channel(
            f"127.0.0.1:{self.port}", grpc.ssl_channel_credentials(read("ca.pem"))), timeout=5)
        with self.assertRaises(CaptureError) as raised:
            anonymous.status()
        self.assertEqual(raised.exception.code, grpc.StatusCode.UNAVAILABLE)
        anonymous.close()


if __name__ == "__main__":
    BSLSD = sys.argv.pop(1)
    unittest.main()
