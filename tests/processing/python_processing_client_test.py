#!/usr/bin/python3
"""bsls-processd driven through the Python client
(clients/python/bsls_client/processing.py), as an automation script drives
it: frames and calibrations rendered with the bsls tool, one frame, a whole
session with measurements, a calibration upload, the calibration cache, bad
input, mutual TLS, round_robin over two replicas and the retries; the
client's own checks of the reply against a stand-in server.

    python_processing_client_test.py BSLS_PROCESSD BSLS [unittest args]
"""
import concurrent.futures
import hashlib
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import zlib

import grpc
import numpy as np

from bsls.v1 import processing_pb2 as pb
from bsls.v1 import processing_pb2_grpc as pb_grpc
try:  # bsls.v1.Artifact has its own file since the daemon stores results too
    from bsls.v1.artifact_pb2 import Artifact
except ImportError:
    Artifact = pb.Artifact
from bsls_client import ProcessingClient, ProcessingError, WorkResult, calibration_id

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "support"))
from bslsd_harness import ServiceProcess, free_port, make_pki  # noqa: E402

PROCESSD = os.environ.get("BSLS_PROCESSD")
BSLS = os.environ.get("BSLS")
INVALID = grpc.StatusCode.INVALID_ARGUMENT


def read_grey_png(path):
    """An 8-bit grey PNG (what bsls simulate writes) as a (height, width) uint8 array."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    at, idat, header = 8, b"", None
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        at += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    width, height, depth, colour, _, _, interlace = header
    assert (depth, colour, interlace) == (8, 0, 0), f"{path}: not 8-bit grey: {header}"
    raw = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(height, width + 1)
    image = np.zeros((height, width), dtype=np.uint8)
    previous = np.zeros(width, dtype=np.uint8)
    for y in range(height):
        kind, row = raw[y, 0], raw[y, 1:]
        if kind == 0:
            out = row.copy()
        elif kind == 1:
            out = np.cumsum(row, dtype=np.uint8)
        elif kind == 2:
            out = row + previous
        else:
            out = np.zeros(width, dtype=np.uint8)
            left = 0
            for x in range(width):
                up, corner = int(previous[x]), int(previous[x - 1]) if x else 0
                if kind == 3:
                    guess = (left + up) >> 1
                else:  # Paeth
                    p = left + up - corner
                    pa, pb_, pc = abs(p - left), abs(p - up), abs(p - corner)
                    guess = left if pa <= pb_ and pa <= pc else (up if pb_ <= pc else corner)
                left = (int(row[x]) + guess) & 0xFF
                out[x] = left
        image[y] = out
        previous = out
    return image


def ply_vertex_count(data):
    """The vertex count in a PLY file's header."""
    header = data[:data.index(b"end_header")].decode()
    for line in header.splitlines():
        if line.startswith("element vertex "):
            return int(line.split()[2])
    raise AssertionError("no vertex element")


def run_bsls(*args):
    r = subprocess.run([BSLS, *args], capture_output=True, text=True)
    assert r.returncode == 0, f"bsls {' '.join(args)}: {r.returncode}: {r.stderr}"
    return r


class Processd(ServiceProcess):
    """A running bsls-processd: `args` are its options after the common ones."""

    def __init__(self, folder, replica, *args, socket_path=None, tcp=False):
        self.dir = folder
        self.socket = socket_path
        self._log = open(os.path.join(folder, replica + ".log"), "w")
        command = [PROCESSD, "--socket", socket_path or "", "--workers", "1",
                   "--replica", replica, "--set", "scratch_dir=" + folder, *args]
        # Its log and (with TCP) the line tcp_port=N once it serves, both on stdout.
        self.process = subprocess.Popen(command, stdout=self._log, stderr=subprocess.STDOUT)
        self.port = None
        deadline = time.monotonic() + 60
        while (tcp and self.port is None) or (socket_path and not os.path.exists(socket_path)):
            if time.monotonic() > deadline or self.process.poll() is not None:
                raise RuntimeError(f"bsls-processd {replica} did not start: {self.log()}")
            ports = [line for line in self.log().splitlines() if line.startswith("tcp_port=")]
            if ports:
                self.port = int(ports[0].split("=")[1])
            time.sleep(0.05)



class ProcessingClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="processd_python_")
        cls.addClassCleanup(shutil.rmtree, cls.dir, ignore_errors=True)
        started = time.monotonic()
        # The two calibration sessions in parallel (each a few seconds), then the rest.
        sessions = [subprocess.Popen(
            [BSLS, "simulate-calibration", "--side", side, "-o", cls.path(side), "--noise", "2",
             "--seed", seed, "--supersampling", "1"], stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE, text=True) for side, seed in (("left", "5"), ("right", "6"))]
        cls.frames, cls.calibrations, cls.png = {}, {}, {}
        for side in ("left", "right"):
            cls.png[side] = cls.path(f"face_{side}.png")
            run_bsls("simulate", "--surface", "face", "--side", side, "-o", cls.png[side],
                     "--noise", "3", "--seed", "4")
            cls.frames[side] = read_grey_png(cls.png[side])
        for process in sessions:
            _, err = process.communicate()
            assert process.returncode == 0, err
        for side in ("left", "right"):
            run_bsls("calibrate", cls.path(side, "session.yaml"), "-o", cls.path(f"{side}.yaml"))
            with open(cls.path(f"{side}.yaml"), "rb") as f:
                cls.calibrations[side] = f.read()
        cls.pki = staticmethod(make_pki(cls.dir, clients=("script",)))
        tls = ["--set", "listen.tcp=127.0.0.1:0",
               "--set", "listen.tls_certificate=" + cls.pki("server.pem"),
               "--set", "listen.tls_key=" + cls.pki("server.key"),
               "--set", "listen.tls_client_ca=" + cls.pki("ca.pem")]
        cls.service = Processd(cls.dir, "py-test", *tls, socket_path=cls.path("processd.sock"),
                               tcp=True)
        cls.addClassCleanup(cls.stop_service)
        cls.client = ProcessingClient.unix(cls.service.socket, timeout=120)
        cls.addClassCleanup(cls.client.close)
        print(f"\ninputs and service ready in {time.monotonic() - started:.1f} s", file=sys.stderr)

    @classmethod
    def stop_service(cls):
        code = cls.service.stop()
        assert code == 0, f"bsls-processd exited with {code}: {cls.service.log()}"

    @classmethod
    def path(cls, *parts):
        return os.path.join(cls.dir, *parts)

    def read(self, name):
        with open(self.pki(name), "rb") as f:
            return f.read()

    # -- the work calls --------------------------------------------------------------------

    def test_process_frame_with_calibration_gives_junctions_and_surface(self):
        stages = []
        done = self.client.process_frame(self.frames["left"], "left",
                                         calibration=self.calibrations["left"], want_surface=True,
                                         want_overlay=True, tag="bed 3",
                                         progress=lambda s, f: stages.append((s, f)))
        self.assertIsInstance(done, WorkResult)
        self.assertEqual(done.attempts, 1)
        self.assertEqual(stages[0][0], "queued")
        self.assertEqual(set(done.files), {"junctions.json", "surface.ply", "overlay.png"})
        side = done.result.sides[0]
        self.assertEqual(side.side, pb.SIDE_LEFT)
        self.assertTrue(side.q_absolute, side.rows_note)
        self.assertGreater(side.junctions, 300)
        self.assertEqual(done.result.replica, "py-test")
        self.assertEqual(done.result.request_tag, "bed 3")
        self.assertEqual(list(done.result.calibration_ids),
                         [calibration_id(self.calibrations["left"])])
        self.assertEqual(done.result.frame_sha256,
                         hashlib.sha256(self.frames["left"].tobytes()).hexdigest())
        junctions = json.loads(done.files["junctions.json"])
        self.assertEqual(len(junctions["junctions"]), side.junctions)
        self.assertEqual(ply_vertex_count(done.files["surface.ply"]), side.vertices)
        self.assertGreater(side.vertices, 5000)
        self.assertTrue(done.files["overlay.png"].startswith(b"\x89PNG"))
        # The same files as `bsls process` on the PNG the frame came from.
        here = self.path("left_here.json"), self.path("left_here.ply")
        run_bsls("process", self.png["left"], "--side", "left", "--calibration",
                 self.path("left.yaml"), "--junctions", here[0], "--surface", here[1])
        with open(here[0]) as f:
            self.assertEqual(json.load(f)["junctions"], junctions["junctions"])
        with open(here[1], "rb") as f:
            self.assertEqual(f.read(), done.files["surface.ply"])
        saved = done.save(self.path("saved"))
        self.assertEqual(sorted(os.listdir(self.path("saved"))), sorted(done.files))
        self.assertEqual(len(saved), 3)

    def test_process_frame_without_calibration_decodes_only(self):
        # A strided view (every other column of a wider array) is sent packed.
        wide = np.repeat(self.frames["right"], 2, axis=1)
        done = self.client.process_frame(wide[:, ::2], "right")
        self.assertFalse(done.result.sides[0].q_absolute)
        self.assertEqual(set(done.files), {"junctions.json"})
        self.assertEqual(done.result.frame_sha256,
                         hashlib.sha256(self.frames["right"].tobytes()).hexdigest())

    def test_reconstruct_session_joins_and_measures(self):
        fractions = []
        square = [(-10, -50), (10, -50), (10, -70), (-10, -70)]
        done = self.client.reconstruct_session(
            self.frames["left"], self.frames["right"], self.calibrations["left"],
            self.calibrations["right"], measurements={"heights": [(0, -60)], "areas": [square]},
            tag="session 7", progress=lambda s, f: fractions.append(f))
        self.assertEqual(fractions, sorted(fractions))
        self.assertEqual(set(done.files), {"surface.ply", "report.json", "measurements.json"})
        result = done.result
        self.assertEqual(result.join_method, "shared-frame")
        self.assertLess(result.seam_rms_mm, 0.3)
        self.assertEqual([s.side for s in result.sides], [pb.SIDE_LEFT, pb.SIDE_RIGHT])
        self.assertTrue(all(s.q_absolute for s in result.sides))
        self.assertEqual(ply_vertex_count(done.files["surface.ply"]), result.vertices)
        self.assertEqual(result.request_tag, "session 7")
        report = json.loads(done.files["report.json"])
        self.assertEqual(report["join"]["method"], "shared-frame")
        self.assertEqual(report["replica"], "py-test")
        ids = {side: calibration_id(self.calibrations[side]) for side in ("left", "right")}
        self.assertEqual(report["calibrations"], ids)
        m = json.loads(done.files["measurements.json"])
        self.assertEqual(len(m["heights"]), 1)
        self.assertGreater(m["heights"][0]["height_mm"]["value"], 0.0)
        self.assertEqual(len(m["areas"]), 1)
        self.assertGreater(m["areas"][0]["area_mm2"]["value"], 399.0)  # a square on a curve
        # By id now that the calibrations are cached; with the side surfaces and junctions.
        again = self.client.reconstruct_session(
            self.frames["left"], self.frames["right"], calibration_id(self.calibrations["left"]),
            calibration_id(self.calibrations["right"]), join="shared", want_side_surfaces=True,
            want_junctions=True)
        self.assertEqual(set(again.files), {"surface.ply", "report.json", "left.ply", "right.ply",
                                            "left.junctions.json", "right.junctions.json"})
        self.assertEqual(again.files["surface.ply"], done.files["surface.ply"])

    def test_calibrate_uploads_the_session_and_caches_the_calibration(self):
        stages = []
        manifest = self.path("left", "session.yaml")
        done = self.client.calibrate(manifest, progress=lambda s, f: stages.append(s))
        self.assertEqual(set(done.files), {"calibration.yaml", "calibration-report.json"})
        yaml_bytes = done.files["calibration.yaml"]
        new_id = "sha256:" + hashlib.sha256(yaml_bytes).hexdigest()
        self.assertEqual(done.result.calibration_id, new_id)
        report = json.loads(done.files["calibration-report.json"])
        self.assertEqual(report["calibration_id"], new_id)
        self.assertEqual(stages[0], "queued")
        self.assertIn("upload", stages)
        self.assertTrue(any(s.startswith("calibrate ") for s in stages), stages)
        held = self.client.get_calibration(new_id)
        self.assertEqual(held.yaml, yaml_bytes)
        self.assertEqual(held.info.id, new_id)
        self.assertEqual((held.info.side, held.info.width, held.info.height),
                         (pb.SIDE_LEFT, 512, 512))
        # The same figures as `bsls calibrate` on the same session. (The files differ in
        # the views' image paths: the service writes its scratch folder's.)
        def figures(text):
            return re.sub(rb"image: [^,]*/", b"image: ", text)
        self.assertEqual(figures(yaml_bytes), figures(self.calibrations["left"]))
        self.assertGreaterEqual(self.client.server_info().cached_calibrations, 1)

    def test_calibrate_uploads_files_of_several_chunks_in_subfolders(self):
        # A copy of the right session with its images in a subfolder and one
        # image padded past 2 MiB (PNG readers ignore what follows IEND).
        session = self.path("right_nested")
        shutil.copytree(self.path("right"), os.path.join(session, "views"))
        with open(self.path("right", "session.yaml")) as f:
            text = f.read().replace("{image: ", "{image: views/")
        with open(os.path.join(session, "session.yaml"), "w") as f:
            f.write(text)
        with open(os.path.join(session, "views", "screen_z000.png"), "ab") as f:
            f.write(os.urandom(2_500_000))
        done = self.client.calibrate(os.path.join(session, "session.yaml"))
        info = self.client.get_calibration(done.result.calibration_id).info
        self.assertEqual(info.side, pb.SIDE_RIGHT)

    def test_put_and_get_calibration(self):
        info = self.client.put_calibration(self.calibrations["right"])
        self.assertEqual(info.id, calibration_id(self.calibrations["right"]))
        self.assertEqual(info.side, pb.SIDE_RIGHT)
        self.assertTrue(info.has_projector_matrix)
        self.assertEqual(self.client.get_calibration(info.id).yaml, self.calibrations["right"])
        with self.assertRaises(ProcessingError) as raised:
            self.client.get_calibration("sha256:" + "0" * 64)
        self.assertEqual(raised.exception.code, grpc.StatusCode.NOT_FOUND)
        with self.assertRaises(ProcessingError) as raised:
            self.client.put_calibration(b"format: bsls-calibration\n")
        self.assertEqual(raised.exception.code, INVALID)
        server = self.client.server_info()
        self.assertEqual((server.replica, server.workers), ("py-test", 1))
        self.assertTrue(server.software_version)

    # -- bad input ---------------------------------------------------------------------------

    def assertRefused(self, call, code=INVALID, says=""):
        with self.assertRaises(ProcessingError) as raised:
            call()
        self.assertEqual(raised.exception.code, code, raised.exception)
        self.assertIn(says, raised.exception.details)
        return raised.exception

    def test_bad_input_is_refused_with_the_field_named(self):
        left, right = self.frames["left"], self.frames["right"]
        cal_left, cal_right = self.calibrations["left"], self.calibrations["right"]
        process, session = self.client.process_frame, self.client.reconstruct_session
        # Refused here, before anything is sent.
        self.assertRefused(lambda: process(np.dstack([left] * 3), "left"), says="2-D uint8")
        self.assertRefused(lambda: process(left.astype(np.uint16), "left"), says="2-D uint8")
        self.assertRefused(lambda: process(left.tolist(), "left"), says="numpy")
        self.assertRefused(lambda: process(np.zeros((5000, 4), np.uint8), "left"), says="4096")
        self.assertRefused(lambda: process(left, "sideways"), says="side")
        self.assertRefused(lambda: process(left, "left", calibration="left.yaml"),
                           says="calibration")
        self.assertRefused(lambda: session(left, right, cal_left, cal_right, join="sideways"),
                           says="join")
        self.assertRefused(lambda: session(left, right, cal_left, cal_right,
                                           measurements={"height": [(0, 0)]}), says="unknown")
        self.assertRefused(lambda: session(left, right, cal_left, cal_right,
                                           measurements={"heights": [(0,)]}),
                           says="measurements.heights[0]")
        # Refused by the service, which names the field.
        self.assertRefused(lambda: process(right, "right", calibration=cal_left), says="left")
        self.assertRefused(lambda: process(left, "left", want_surface=True), says="want_surface")
        self.assertRefused(lambda: process(left, "left", calibration=cal_left[:len(cal_left) // 2]),
                           says="calibration")
        self.assertRefused(lambda: process(left, "left", tag="x" * 300), says="request_tag")
        self.assertRefused(lambda: process(left[:100, :100], "left", calibration=cal_left))
        self.assertRefused(lambda: session(left, right, cal_right, cal_left), says="right side")
        self.assertRefused(lambda: session(left, right, cal_left, cal_right,
                                           measurements={"distances": [[(0, 0), (1, 1), (2, 2)]]}),
                           says="measurements.distances[0]")
        self.assertRefused(lambda: process(left, "left", calibration="sha256:" + "1" * 64),
                           code=grpc.StatusCode.NOT_FOUND, says="py-test")
        # Manifests: an image outside the folder or missing is refused here, a bad one there.
        session_folder = self.path("left")
        for name, image in (("escape.yaml", "../face_left.png"), ("absolute.yaml", "/etc/passwd"),
                            ("missing.yaml", "nowhere.png")):
            with open(self.path("left", "session.yaml")) as f:
                text = f.read().replace("target_z000.png", image)
            with open(os.path.join(session_folder, name), "w") as f:
                f.write(text)
            self.assertRefused(lambda: self.client.calibrate(os.path.join(session_folder, name)),
                               says=image)
        with open(os.path.join(session_folder, "flat.yaml"), "w") as f:
            f.write("side: left\ntarget: {rows: 8, cols: 8, pitch_mm: 6.5, square_mm: 4}\n"
                    "camera_views:\n  - {image: target_z000.png, z_mm: 0}\n"
                    "screen_views:\n  - {image: screen_z000.png, z_mm: 0}\n")
        self.assertRefused(lambda: self.client.calibrate(os.path.join(session_folder, "flat.yaml")),
                           says="two distinct z_mm")
        # And the replica still serves.
        self.assertEqual(self.client.server_info().busy, 0)

    # -- connections -------------------------------------------------------------------------

    def test_mutual_tls_needs_a_client_certificate_of_the_ca(self):
        port = self.service.port
        for target in (f"localhost:{port}", f"127.0.0.1:{port}",
                       f"ipv4:127.0.0.1:{port},127.0.0.1:{port}", f"dns:///localhost:{port}"):
            with ProcessingClient.tcp(target, self.read("ca.pem"), self.pki("script.pem"),
                                      self.pki("script.key"), timeout=30) as remote:
                self.assertEqual(remote.server_info().replica, "py-test", target)
        with ProcessingClient.tcp(f"localhost:{port}", self.pki("ca.pem"), self.pki("script.pem"),
                                  self.pki("script.key"), timeout=60) as remote:
            done = remote.process_frame(self.frames["left"], "left")
            self.assertGreater(done.result.sides[0].junctions, 300)
        # Without a client certificate, or with one of another CA, the handshake fails.
        other = tempfile.mkdtemp(dir=self.dir)
        stranger = make_pki(other, clients=("script",))
        anonymous = grpc.secure_channel(f"localhost:{port}",
                                        grpc.ssl_channel_credentials(self.read("ca.pem")))
        for client in (ProcessingClient(anonymous, timeout=5, attempts=2),
                       ProcessingClient.tcp(f"localhost:{port}", self.pki("ca.pem"),
                                            stranger("script.pem"), stranger("script.key"),
                                            timeout=5, attempts=2)):
            with client:
                error = self.assertRefused(client.server_info, grpc.StatusCode.UNAVAILABLE)
                self.assertEqual(error.attempts, 2)
                self.assertRefused(lambda: client.process_frame(self.frames["left"], "left"),
                                   grpc.StatusCode.UNAVAILABLE)

    def test_plain_tcp_is_for_loopback_targets_only(self):
        for target in ("10.0.0.1:7000", "processd.clinic:7000", "dns:///processd:7000",
                       "ipv4:127.0.0.1:7001,10.0.0.2:7002", "[2001:db8::1]:7000"):
            with self.assertRaises(ValueError, msg=target):
                ProcessingClient.loopback(target)
        for target in ("localhost:7000", "127.0.0.2:7000", "[::1]:7000", "dns:///localhost:7000",
                       "ipv4:127.0.0.1:7001,127.0.0.1:7002", "ipv6:[::1]:7000"):
            ProcessingClient.loopback(target).close()

    def test_round_robin_spreads_calls_and_retries_a_full_replica_elsewhere(self):
        replicas = []
        try:
            for name in ("rr-a", "rr-b"):
                replicas.append(Processd(self.dir, name, "--set", "listen.tcp=127.0.0.1:0", "--set",
                                         "listen.plaintext_loopback=true", "--set", "queue=0",
                                         tcp=True))
            a, b = (r.port for r in replicas)
            both = ProcessingClient.loopback(f"ipv4:127.0.0.1:{a},127.0.0.1:{b}", timeout=60)
            seen = set()
            deadline = time.monotonic() + 30
            while seen != {"rr-a", "rr-b"} and time.monotonic() < deadline:
                seen.add(both.server_info().replica)
            self.assertEqual(seen, {"rr-a", "rr-b"})

            # rr-a's only place taken by an upload that does not end.
            only_a = ProcessingClient.loopback(f"127.0.0.1:{a}", timeout=60, attempts=1)
            release = threading.Event()

            def endless_upload():
                yield pb.CalibrateRequest(manifest=pb.CalibrationManifest(yaml=b"side: left\n"))
                release.wait(60)
            holder = pb_grpc.ProcessingStub(only_a._channel).Calibrate(endless_upload(),
                                                                        timeout=60)
            self.assertEqual(next(holder).progress.stage, "queued")
            try:
                error = self.assertRefused(
                    lambda: only_a.process_frame(self.frames["left"], "left"),
                    grpc.StatusCode.RESOURCE_EXHAUSTED, says="rr-a")
                self.assertEqual(error.attempts, 1)
                # Through round_robin every call ends on rr-b, some after a retry.
                for _ in range(4):
                    done = both.process_frame(self.frames["left"], "left")
                    self.assertEqual(done.result.replica, "rr-b")
                # rr-a itself once the upload is cancelled: its retries wait for it.
                patient = ProcessingClient.loopback(f"127.0.0.1:{a}", timeout=60, attempts=6,
                                                    backoff=0.2)
                threading.Timer(1.0, holder.cancel).start()
                done = patient.process_frame(self.frames["left"], "left")
                self.assertEqual(done.result.replica, "rr-a")
                self.assertGreater(done.attempts, 1)
            finally:
                holder.cancel()
                release.set()
            self.assertGreaterEqual(only_a.server_info().rejected, 2)
            for client in (both, only_a, patient):
                client.close()
        finally:
            for r in replicas:
                self.assertEqual(r.stop(), 0, r.log())

    def test_nobody_listening_is_unavailable_after_every_attempt(self):
        client = ProcessingClient.loopback(f"127.0.0.1:{free_port()}", timeout=5, attempts=3,
                                           backoff=0.1)
        started = time.monotonic()
        error = self.assertRefused(lambda: client.process_frame(self.frames["left"], "left"),
                                   grpc.StatusCode.UNAVAILABLE)
        self.assertEqual(error.attempts, 3)
        self.assertGreaterEqual(time.monotonic() - started, 0.3)  # 0.1 s + 0.2 s of back-off
        client.close()


class StandInService(pb_grpc.ProcessingServicer):
    """Replies a test chooses: `script` is a list of functions (request, context) -> events,
    one per call."""

    def __init__(self):
        self.script = []
        self.calls = 0

    def ProcessFrame(self, request, context):
        self.calls += 1
        yield from self.script.pop(0)(request, context)


def artifact_events(name, data, chunk=4, damage=None):
    """The artifact chunks of `data` as the service sends them; `damage` edits the list."""
    events = []
    for offset in range(0, max(len(data), 1), chunk):
        piece = data[offset:offset + chunk]
        events.append(pb.WorkEvent(artifact=Artifact(
            name=name, offset=offset, total_size=len(data), data=piece,
            last=offset + chunk >= len(data))))
    events[-1].artifact.sha256 = hashlib.sha256(data).hexdigest()
    return damage(events) if damage else events


class ClientChecksTest(unittest.TestCase):
    """The client against a stand-in server: reassembly, damage, retries."""

    @classmethod
    def setUpClass(cls):
        cls.stand_in = StandInService()
        cls.server = grpc.server(concurrent.futures.ThreadPoolExecutor(max_workers=4))
        pb_grpc.add_ProcessingServicer_to_server(cls.stand_in, cls.server)
        port = cls.server.add_insecure_port("127.0.0.1:0")
        cls.server.start()
        cls.client = ProcessingClient.loopback(f"127.0.0.1:{port}", timeout=10, backoff=0.01)
        cls.frame = np.arange(64, dtype=np.uint8).reshape(8, 8)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.stop(None)

    def setUp(self):
        self.stand_in.script, self.stand_in.calls = [], 0

    def reply(self, *events, status=None):
        def call(request, context):
            yield from events
            if status:
                context.abort(*status)
        return call

    def test_artifacts_are_reassembled_and_checked(self):
        data = b"0123456789abcdefg"
        self.stand_in.script.append(self.reply(
            *artifact_events("a.bin", data), *artifact_events("empty.txt", b""),
            pb.WorkEvent(result=pb.Result(replica="stand-in"))))
        done = self.client.process_frame(self.frame, "left")
        self.assertEqual(done.files, {"a.bin": data, "empty.txt": b""})
        self.assertEqual(done.result.replica, "stand-in")

    def test_damaged_replies_are_data_loss(self):
        data = b"0123456789abcdefg"
        def last(events, **fields):  # the last chunk changed
            changed = pb.WorkEvent()
            changed.CopyFrom(events[-1])
            for key, value in fields.items():
                setattr(changed.artifact, key, value)
            return events[:-1] + [changed]

        def early_end(events):  # the third chunk (of five) marked last
            changed = pb.WorkEvent()
            changed.CopyFrom(events[2])
            changed.artifact.last = True
            return events[:2] + [changed]
        damages = {
            "SHA-256 does not match": lambda e: last(e, data=b"G"),
            "a chunk at offset 0 after 4 bytes": lambda e: [e[0]] + e,
            "more bytes than the 17 announced": lambda e: last(e, data=b"gh"),
            "ended after 12 of 17 bytes": early_end,
            "a.bin: sent twice": lambda e: e + e,
            "unfinished: a.bin": lambda e: e[:-1],
        }
        for says, damage in damages.items():
            with self.subTest(says):
                self.stand_in.script = [self.reply(*artifact_events("a.bin", data, damage=damage),
                                                   pb.WorkEvent(result=pb.Result()))]
                self.stand_in.calls = 0
                with self.assertRaises(ProcessingError) as raised:
                    self.client.process_frame(self.frame, "left")
                self.assertEqual(raised.exception.code, grpc.StatusCode.DATA_LOSS)
                self.assertIn(says, raised.exception.details)
                self.assertEqual(self.stand_in.calls, 1)  # never retried
        self.stand_in.script = [self.reply(pb.WorkEvent(progress=pb.Progress(stage="queued")))]
        with self.assertRaises(ProcessingError) as raised:
            self.client.process_frame(self.frame, "left")
        self.assertEqual(raised.exception.code, grpc.StatusCode.DATA_LOSS)
        self.assertIn("without its result", raised.exception.details)

    def test_busy_and_unavailable_are_retried_before_the_result_only(self):
        busy = (grpc.StatusCode.RESOURCE_EXHAUSTED, "full")
        gone = (grpc.StatusCode.UNAVAILABLE, "draining")
        ok = self.reply(pb.WorkEvent(result=pb.Result(replica="third time")))
        self.stand_in.script = [self.reply(status=busy), self.reply(status=gone), ok]
        done = self.client.process_frame(self.frame, "left")
        self.assertEqual((done.attempts, done.result.replica), (3, "third time"))
        # Four attempts, then the last status.
        self.stand_in.script = [self.reply(status=busy)] * 4
        with self.assertRaises(ProcessingError) as raised:
            self.client.process_frame(self.frame, "left")
        self.assertEqual((raised.exception.code, raised.exception.attempts),
                         (grpc.StatusCode.RESOURCE_EXHAUSTED, 4))
        # Not after the result, and not other codes.
        self.stand_in.calls = 0
        self.stand_in.script = [self.reply(pb.WorkEvent(result=pb.Result()), status=gone)]
        with self.assertRaises(ProcessingError) as raised:
            self.client.process_frame(self.frame, "left")
        self.assertEqual((raised.exception.code, self.stand_in.calls),
                         (grpc.StatusCode.UNAVAILABLE, 1))
        self.stand_in.script, self.stand_in.calls = [self.reply(
            status=(grpc.StatusCode.FAILED_PRECONDITION, "no reference line"))], 0
        with self.assertRaises(ProcessingError) as raised:
            self.client.process_frame(self.frame, "left")
        self.assertEqual((raised.exception.code, raised.exception.details, self.stand_in.calls),
                         (grpc.StatusCode.FAILED_PRECONDITION, "no reference line", 1))

    def test_the_frame_goes_packed_with_its_side(self):
        seen = []

        def record(request, context):
            seen.append(request)
            yield pb.WorkEvent(result=pb.Result())
        self.stand_in.script = [record]
        self.client.process_frame(self.frame[:, 2:7], "right", calibration=b"cal", tag="t")
        frame = seen[0].frame
        self.assertEqual((frame.width, frame.height, frame.stride), (5, 8, 5))
        self.assertEqual(frame.pixels, self.frame[:, 2:7].tobytes())
        self.assertEqual((seen[0].side, seen[0].calibration.yaml, seen[0].request_tag),
                         (pb.SIDE_RIGHT, b"cal", "t"))

    def test_a_progress_callback_that_raises_stops_the_call(self):
        self.stand_in.script = [self.reply(pb.WorkEvent(progress=pb.Progress(stage="queued")),
                                           pb.WorkEvent(result=pb.Result()))]

        def stop(stage, fraction):
            raise KeyboardInterrupt
        with self.assertRaises(KeyboardInterrupt):
            self.client.process_frame(self.frame, "left", progress=stop)


if __name__ == "__main__":
    if len(sys.argv) > 2 and not sys.argv[1].startswith("-"):
        PROCESSD, BSLS = sys.argv.pop(1), sys.argv.pop(1)
    if not (PROCESSD and BSLS):
        sys.exit("usage: python_processing_client_test.py BSLS_PROCESSD BSLS [unittest args]")
    unittest.main(verbosity=2)
