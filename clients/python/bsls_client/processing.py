"""ProcessingClient: the processing service's API (proto/bsls/v1/processing.proto) in Python.

    from bsls_client import ProcessingClient
    with ProcessingClient.unix("/run/bsls-processd/processd.sock") as service:
        done = service.reconstruct_session(left, right, left_yaml, right_yaml,
                                           measurements={"heights": [(0, -60)]})
        done.result.seam_rms_mm, done.files["surface.ply"], done.files["measurements.json"]

Work calls (process_frame, reconstruct_session, calibrate) return a WorkResult:
the Result message, the output files reassembled and checked (chunk order,
size, SHA-256), and how many attempts the call took. A call that fails with
UNAVAILABLE or RESOURCE_EXHAUSTED before its Result is tried again after a
back-off (0.1 s, doubling; 4 attempts by default), which gRPC's round_robin
sends to the next replica. Every other failure raises ProcessingError with the
gRPC status code and the service's message; bad arguments are refused with
INVALID_ARGUMENT before anything is sent.
"""
from __future__ import annotations

import dataclasses
import hashlib
import ipaddress
import os
import posixpath
import time
from typing import Callable, Dict, Iterator, List, Optional, Tuple, Union

import grpc
import numpy as np

from bsls.v1 import capture_pb2
from bsls.v1 import processing_pb2 as pb
from bsls.v1 import processing_pb2_grpc as pb_grpc

CHUNK_BYTES = 1 << 20  # upload chunks, as the service's own artifacts
MAX_FRAME_SIDE = 4096  # the service's limit on each side of a frame
CHANNEL_OPTIONS = [
    ("grpc.lb_policy_name", "round_robin"),
    ("grpc.max_receive_message_length", 8 << 20),  # replies come in 1 MiB chunks
    ("grpc.max_send_message_length", 40 << 20),    # two 4096 x 4096 frames
    # A replica that went away is tried again soon after it comes back.
    ("grpc.initial_reconnect_backoff_ms", 200),
    ("grpc.max_reconnect_backoff_ms", 2000),
]
RETRYABLE = (grpc.StatusCode.UNAVAILABLE, grpc.StatusCode.RESOURCE_EXHAUSTED)



def _enum_names(enum_type, prefix: str) -> Dict[str, int]:
    """{name: number} of the values of a proto enum, each name lower case without
    `prefix` ("JOIN_AUTO" -> "auto"), the UNSPECIFIED value left out: the names the
    contracts give, read from the protos' descriptors rather than copied here."""
    return {v.name[len(prefix):].lower(): v.number for v in enum_type.DESCRIPTOR.values
            if v.name.startswith(prefix) and not v.name.endswith("_UNSPECIFIED")}


_SIDES = _enum_names(pb.Side, "SIDE_")
_JOINS = _enum_names(pb.ReconstructSessionRequest.Join, "JOIN_")
_REFERENCES = _enum_names(pb.MeasurementPlan.Reference, "REFERENCE_")
_MEASUREMENT_KEYS = {f.name for f in pb.MeasurementPlan.DESCRIPTOR.fields}

Calibration = Union[bytes, str]  # the file's bytes, or the id "sha256:<hex>" of a cached one
Point = Tuple[float, float]
Progress = Callable[[str, float], None]


class ProcessingError(Exception):
    """A call the service refused or could not complete: `code` is the grpc.StatusCode."""

    def __init__(self, method: str, code: grpc.StatusCode, details: str, attempts: int = 1):
        self.method = method
        self.code = code
        self.details = details
        self.attempts = attempts
        super().__init__(f"{method}: {code.name}: {details}")

    @classmethod
    def from_rpc(cls, method: str, error: grpc.RpcError, attempts: int = 1) -> "ProcessingError":
        """The error of a failed gRPC call."""
        return cls(method, error.code(), error.details() or "", attempts)


def _invalid(method: str, details: str) -> ProcessingError:
    return ProcessingError(method, grpc.StatusCode.INVALID_ARGUMENT, details)


@dataclasses.dataclass
class WorkResult:
    """A finished work call: the Result, the output files by name, the attempts it took."""
    result: pb.Result
    files: Dict[str, bytes]
    attempts: int

    def save(self, folder: str) -> List[str]:
        """Writes every output file into `folder` (made if missing); returns their paths."""
        os.makedirs(folder, exist_ok=True)
        paths = []
        for name, data in sorted(self.files.items()):
            path = os.path.join(folder, os.path.basename(name))
            with open(path, "wb") as out:
                out.write(data)
            paths.append(path)
        return paths


class _Artifacts:
    """Output files put together from their chunks; DATA_LOSS on any inconsistency."""

    def __init__(self, method: str):
        self._method = method
        self._partial: Dict[str, Tuple[int, bytearray]] = {}  # name -> (total_size, bytes)
        self.files: Dict[str, bytes] = {}

    def _damaged(self, details: str) -> ProcessingError:
        return ProcessingError(self._method, grpc.StatusCode.DATA_LOSS, details)

    def add(self, chunk) -> None:  # a bsls.v1.Artifact
        name = chunk.name
        if not name:
            raise self._damaged("an artifact chunk without a name")
        if name in self.files:
            raise self._damaged(f"{name}: sent twice")
        total, data = self._partial.setdefault(name, (chunk.total_size, bytearray()))
        if chunk.offset != len(data):
            raise self._damaged(f"{name}: a chunk at offset {chunk.offset} after {len(data)} bytes")
        if chunk.total_size != total or len(data) + len(chunk.data) > total:
            raise self._damaged(f"{name}: more bytes than the {total} announced")
        data += chunk.data
        if not chunk.last:
            return
        if len(data) != total:
            raise self._damaged(f"{name}: ended after {len(data)} of {total} bytes")
        if hashlib.sha256(data).hexdigest() != chunk.sha256.lower():
            raise self._damaged(f"{name}: SHA-256 does not match (damaged in transit)")
        self.files[name] = bytes(data)
        del self._partial[name]

    def unfinished(self) -> List[str]:
        return sorted(self._partial)


def _host_of(address: str) -> str:
    """The host of "host:port", "[v6]:port" or "host"."""
    if address.startswith("["):
        close = address.find("]")
        return address[1:close] if close >= 0 else address
    if address.count(":") == 1:
        return address.rsplit(":", 1)[0]
    return address  # a bare name, or a bare IPv6 address


def _addresses(target: str) -> List[str]:
    """The "host:port" addresses of a gRPC target (ipv4:/ipv6: lists, dns:, or plain)."""
    for scheme in ("ipv4:", "ipv6:"):
        if target.startswith(scheme):
            return [a for a in target[len(scheme):].split(",") if a]
    if target.startswith("dns:"):
        rest = target[4:]
        if rest.startswith("//"):
            rest = rest[2:].split("/", 1)[-1]  # drop the authority (a DNS server) if any
        return [rest]
    return [target]


def _is_loopback_host(host: str) -> bool:
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def is_loopback_target(target: str) -> bool:
    """True when every address of the target is this machine's loopback (or a Unix socket)."""
    if target.startswith(("unix:", "unix-abstract:")):
        return True
    addresses = _addresses(target)
    return bool(addresses) and all(_is_loopback_host(_host_of(a)) for a in addresses)


def _pem(value: Union[bytes, str, os.PathLike], what: str) -> bytes:
    """PEM bytes as given, or read from a file path."""
    if isinstance(value, bytes):
        data = value
    else:
        with open(value, "rb") as f:
            data = f.read()
    if b"-----BEGIN" not in data:
        raise ValueError(f"{what}: not PEM data")
    return data


def _frame(image, field: str, method: str) -> capture_pb2.Frame:
    """A bsls.v1.Frame of a 2-D uint8 array (packed rows: stride = width)."""
    if not isinstance(image, np.ndarray):
        raise _invalid(method, f"{field}: expected a 2-D uint8 numpy array, "
                               f"not {type(image).__name__}")
    if image.ndim != 2 or image.dtype != np.uint8:
        raise _invalid(method, f"{field}: expected a 2-D uint8 array (8-bit grey), "
                               f"not {image.ndim}-D {image.dtype} of shape {image.shape}")
    height, width = image.shape
    if not (1 <= width <= MAX_FRAME_SIDE and 1 <= height <= MAX_FRAME_SIDE):
        raise _invalid(method, f"{field}: {width} x {height} pixels; each side must be "
                               f"1..{MAX_FRAME_SIDE}")
    return capture_pb2.Frame(width=width, height=height, stride=width,
                             pixels=np.ascontiguousarray(image).tobytes())


def _calibration(value: Optional[Calibration], field: str, method: str
                 ) -> Optional[pb.CalibrationSource]:
    if value is None:
        return None
    if isinstance(value, (bytes, bytearray, memoryview)):
        return pb.CalibrationSource(yaml=bytes(value))
    if isinstance(value, str) and value.startswith("sha256:"):
        return pb.CalibrationSource(id=value)
    raise _invalid(method, f"{field}: give the calibration file's bytes or its id "
                           f"\"sha256:<hex>\", not {value!r:.80}")


def _point(value, field: str, method: str) -> pb.PointXY:
    try:
        x, y = value
        return pb.PointXY(x=float(x), y=float(y))
    except (TypeError, ValueError):
        raise _invalid(method, f"{field}: a point is (x, y) in millimetres, not {value!r:.80}") \
            from None


def _polygon(points, field: str, method: str) -> pb.Polygon:
    try:
        items = list(points)
    except TypeError:
        raise _invalid(method, f"{field}: a list of (x, y) points, not {points!r:.80}") from None
    return pb.Polygon(points=[_point(p, f"{field}[{i}]", method) for i, p in enumerate(items)])


def _plan(measurements: Optional[dict], method: str) -> Optional[pb.MeasurementPlan]:
    """The MeasurementPlan of a dict (see reconstruct_session); INVALID_ARGUMENT if malformed."""
    if not measurements:
        return None
    unknown = set(measurements) - _MEASUREMENT_KEYS
    if unknown:
        raise _invalid(method, f"measurements: unknown keys {sorted(unknown)}; "
                               f"known are {sorted(_MEASUREMENT_KEYS)}")
    plan = pb.MeasurementPlan()
    for i, p in enumerate(measurements.get("heights", ())):
        plan.heights.append(_point(p, f"measurements.heights[{i}]", method))
    for key in ("distances", "areas", "lesions"):
        for i, polygon in enumerate(measurements.get(key, ())):
            getattr(plan, key).append(_polygon(polygon, f"measurements.{key}[{i}]", method))
    reference = measurements.get("reference")
    if reference is not None:
        if reference not in _REFERENCES:
            raise _invalid(method, f"measurements.reference: one of {sorted(_REFERENCES)}, "
                                   f"not {reference!r}")
        plan.reference = _REFERENCES[reference]
    if measurements.get("ring_mm") is not None:
        plan.ring_mm = float(measurements["ring_mm"])
    return plan


def _manifest_images(text: bytes, method: str) -> List[str]:
    """The relative paths of every image a calibration manifest lists, each once, in order."""
    import yaml  # python3-yaml; only calibrate() needs it

    try:
        # BaseLoader keeps every scalar a string, as the service's YAML reader sees it.
        root = yaml.load(text, Loader=yaml.BaseLoader)
    except yaml.YAMLError as error:
        raise _invalid(method, f"manifest: not valid YAML: {error}") from None
    if not isinstance(root, dict):
        raise _invalid(method, "manifest: not a manifest (expected a mapping)")
    paths: List[str] = []
    for key, views in root.items():  # camera_views, screen_views, reference_views
        if not isinstance(views, list):
            continue
        for i, view in enumerate(views):
            if not isinstance(view, dict) or "image" not in view:
                continue
            path = view["image"]
            if not isinstance(path, str) or not path:
                raise _invalid(method, f"manifest: {key}[{i}].image is not a path")
            parts = path.split("/")
            if path.startswith("/") or ".." in parts:
                raise _invalid(method, f"manifest: {key}[{i}].image {path}: must be relative to "
                                       "the manifest's folder, without \"..\"")
            path = posixpath.normpath(path)
            if path not in paths:
                paths.append(path)
    return paths


class ProcessingClient:
    """A connection to bsls-processd (one replica or several); every attempt has a deadline."""

    def __init__(self, channel: grpc.Channel, timeout: float = 300.0, attempts: int = 4,
                 backoff: float = 0.1):
        self._channel = channel
        self._stub = pb_grpc.ProcessingStub(channel)
        self.timeout = timeout    # seconds per attempt
        self.attempts = attempts  # tries of a work call that meets UNAVAILABLE / RESOURCE_EXHAUSTED
        self.backoff = backoff    # seconds before the second try; doubles after each

    @classmethod
    def unix(cls, socket_path: str, **options) -> "ProcessingClient":
        """Connects to a replica's Unix socket (plain; the socket's group decides who may)."""
        target = socket_path if socket_path.startswith("unix:") else f"unix:{socket_path}"
        return cls(grpc.insecure_channel(target, options=CHANNEL_OPTIONS), **options)

    @classmethod
    def tcp(cls, target: str, ca, certificate, key, server_name: Optional[str] = None,
            **options) -> "ProcessingClient":
        """Connects with mutual TLS (PEM bytes or file paths) to one replica or several."""
        # target: "host:port", "ipv4:h:p,h:p" or "dns:///name:port". The replicas'
        # certificates must name `server_name`, by default the host of the first address
        # (gRPC's own default for an address list is the whole list, which no
        # certificate names).
        credentials = grpc.ssl_channel_credentials(root_certificates=_pem(ca, "ca"),
                                                   private_key=_pem(key, "key"),
                                                   certificate_chain=_pem(certificate,
                                                                          "certificate"))
        addresses = _addresses(target)
        name = server_name or (_host_of(addresses[0]) if addresses else "")
        channel_options = list(CHANNEL_OPTIONS)
        if name:
            channel_options.append(("grpc.ssl_target_name_override", name))
        return cls(grpc.secure_channel(target, credentials, options=channel_options), **options)

    @classmethod
    def loopback(cls, target: str, **options) -> "ProcessingClient":
        """Connects in plain TCP to replicas on this machine; ValueError for any other host."""
        if not is_loopback_target(target):
            raise ValueError(f"{target}: plain TCP is for loopback replicas only "
                             "(localhost, 127.0.0.0/8, [::1]); use tcp() with mutual TLS")
        return cls(grpc.insecure_channel(target, options=CHANNEL_OPTIONS), **options)

    def close(self) -> None:
        """Closes the channel (calls under way are cancelled)."""
        self._channel.close()

    def __enter__(self) -> "ProcessingClient":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- work calls -----------------------------------------------------------------------

    def _work(self, method: str, request: Callable[[], object],
              progress: Optional[Progress]) -> WorkResult:
        """Runs a streaming work call with retries; `request()` gives each attempt's request."""
        delay = self.backoff
        attempts = max(1, self.attempts)
        for attempt in range(1, attempts + 1):
            call = getattr(self._stub, method)(request(), timeout=self.timeout)
            artifacts = _Artifacts(method)
            result = None
            finished = False
            try:
                for event in call:
                    kind = event.WhichOneof("event")
                    if kind == "progress":
                        if progress is not None:
                            progress(event.progress.stage, event.progress.fraction)
                    elif kind == "artifact":
                        artifacts.add(event.artifact)
                    elif kind == "result":
                        result = event.result
                finished = True
            except grpc.RpcError as error:
                finished = True
                if result is None and error.code() in RETRYABLE and attempt < attempts:
                    time.sleep(delay)
                    delay *= 2
                    continue
                raise ProcessingError.from_rpc(method, error, attempt) from None
            except ProcessingError as error:
                error.attempts = attempt
                raise
            finally:
                if not finished:
                    call.cancel()  # damaged reply, or the progress callback raised
            if result is None or artifacts.unfinished():
                unfinished = artifacts.unfinished()
                raise ProcessingError(
                    method, grpc.StatusCode.DATA_LOSS, "the reply ended without its result" +
                    (f" (unfinished: {', '.join(unfinished)})" if unfinished else ""), attempt)
            return WorkResult(result, artifacts.files, attempt)
        raise AssertionError("unreachable")

    def process_frame(self, image: np.ndarray, side: str, calibration: Optional[Calibration] = None,
                      want_surface: bool = False, want_overlay: bool = False, tag: str = "",
                      progress: Optional[Progress] = None,
                      decode: Optional[pb.DecodeOptions] = None,
                      surface: Optional[pb.SurfaceOptions] = None) -> WorkResult:
        """Decodes one frame: junctions.json, and overlay.png / surface.ply when asked for."""
        # image: 2-D uint8 (rows x columns), sent packed; side: "left" or "right";
        # calibration: the file's bytes or the id of a cached one (absolute q; needed
        # for want_surface); progress(stage, fraction) as the work goes on (raising
        # from it cancels the call); decode / surface: the proto's options.
        method = "ProcessFrame"
        if side not in _SIDES:
            raise _invalid(method, f"side: one of {sorted(_SIDES)}, not {side!r}")
        request = pb.ProcessFrameRequest(frame=_frame(image, "frame", method), side=_SIDES[side],
                                         want_surface=want_surface, want_overlay=want_overlay,
                                         request_tag=tag)
        source = _calibration(calibration, "calibration", method)
        if source is not None:
            request.calibration.CopyFrom(source)
        if decode is not None:
            request.decode.CopyFrom(decode)
        if surface is not None:
            request.surface.CopyFrom(surface)
        return self._work(method, lambda: request, progress)

    def reconstruct_session(self, left: np.ndarray, right: np.ndarray,
                            left_calibration: Calibration, right_calibration: Calibration,
                            join: str = "auto", measurements: Optional[dict] = None,
                            want_side_surfaces: bool = False, want_junctions: bool = False,
                            tag: str = "", progress: Optional[Progress] = None,
                            surface: Optional[pb.SurfaceOptions] = None) -> WorkResult:
        """Reconstructs, joins and measures both sides: surface.ply, report.json and more."""
        # join: "auto", "shared" or "features"; measurements: {"heights": [(x, y)],
        # "distances": [((x, y), (x, y))], "areas": [[(x, y), ...]], "lesions":
        # [[(x, y), ...]], "reference": "plane"|"quadric"|"cubic", "ring_mm": r}, world
        # mm, gives measurements.json; want_side_surfaces: left.ply, right.ply;
        # want_junctions: left.junctions.json, right.junctions.json.
        method = "ReconstructSession"
        if join not in _JOINS:
            raise _invalid(method, f"join: one of {sorted(_JOINS)}, not {join!r}")
        request = pb.ReconstructSessionRequest(
            left=_frame(left, "left", method), right=_frame(right, "right", method),
            join=_JOINS[join], want_side_surfaces=want_side_surfaces,
            want_junctions=want_junctions, request_tag=tag)
        for field, value in (("left_calibration", left_calibration),
                             ("right_calibration", right_calibration)):
            source = _calibration(value, field, method)
            if source is None:
                raise _invalid(method, f"{field}: a calibration is needed for each side")
            getattr(request, field).CopyFrom(source)
        plan = _plan(measurements, method)
        if plan is not None:
            request.measurements.CopyFrom(plan)
        if surface is not None:
            request.surface.CopyFrom(surface)
        return self._work(method, lambda: request, progress)

    def measure(self, surface_ply: bytes, measurements: dict,
                baseline_ply: Optional[bytes] = None, baseline_shares_frame: bool = False,
                tag: str = "", progress: Optional[Progress] = None) -> WorkResult:
        """Measures a surface (PLY bytes, world mm): measurements.json with every figure,
        its uncertainty and a table; lesions against `baseline_ply` when given."""
        method = "Measure"
        plan = _plan(measurements, method)
        if plan is None:
            raise _invalid(method, "measurements: give at least one figure")
        request = pb.MeasureRequest(surface_ply=surface_ply, measurements=plan,
                                    baseline_ply=baseline_ply or b"",
                                    baseline_shares_frame=baseline_shares_frame,
                                    request_tag=tag)
        return self._work(method, lambda: request, progress)

    def calibrate(self, manifest_path: str, progress: Optional[Progress] = None,
                  tag: str = "") -> WorkResult:
        """Calibrates a side from a manifest and its images: calibration.yaml, cached by its id."""
        # Every image the manifest lists (relative to its folder, without "..") is
        # uploaded in 1 MiB chunks; result.calibration_id is the new file's id and the
        # files are calibration.yaml and calibration-report.json.
        method = "Calibrate"
        with open(manifest_path, "rb") as f:
            manifest = f.read()
        folder = os.path.dirname(os.path.abspath(manifest_path))
        files = []
        for path in _manifest_images(manifest, method):
            local = os.path.join(folder, *path.split("/"))
            if not os.path.isfile(local):
                raise _invalid(method, f"manifest: image {path} does not exist ({local})")
            files.append((path, local))

        def upload() -> Iterator[pb.CalibrateRequest]:
            yield pb.CalibrateRequest(manifest=pb.CalibrationManifest(yaml=manifest,
                                                                      request_tag=tag))
            for path, local in files:
                with open(local, "rb") as f:
                    offset = 0
                    data = f.read(CHUNK_BYTES)
                    while True:
                        following = f.read(CHUNK_BYTES) if data else b""
                        yield pb.CalibrateRequest(file=pb.FileChunk(
                            path=path, offset=offset, data=data, last=not following))
                        offset += len(data)
                        if not following:
                            break
                        data = following

        return self._work(method, upload, progress)

    # -- the calibration cache and the replica --------------------------------------------

    def _unary(self, method: str, request):
        delay = self.backoff
        attempts = max(1, self.attempts)
        for attempt in range(1, attempts + 1):
            try:
                return getattr(self._stub, method)(request, timeout=self.timeout)
            except grpc.RpcError as error:
                if error.code() == grpc.StatusCode.UNAVAILABLE and attempt < attempts:
                    time.sleep(delay)
                    delay *= 2
                    continue
                raise ProcessingError.from_rpc(method, error, attempt) from None
        raise AssertionError("unreachable")

    def put_calibration(self, yaml_bytes: bytes) -> pb.CalibrationInfo:
        """Caches a calibration file on the replica; returns its id ("sha256:<hex>") and facts."""
        return self._unary("PutCalibration", pb.PutCalibrationRequest(yaml=bytes(yaml_bytes)))

    def get_calibration(self, calibration_id: str) -> pb.CalibrationFile:
        """A calibration the replica holds (info and yaml); NOT_FOUND when it does not."""
        return self._unary("GetCalibration", pb.GetCalibrationRequest(id=calibration_id))

    def server_info(self) -> pb.ServerInfo:
        """The replica's version, name, pool size and load, and cached calibrations."""
        return self._unary("GetServerInfo", pb.GetServerInfoRequest())


def calibration_id(yaml_bytes: bytes) -> str:
    """The id the service gives a calibration file: "sha256:" + hex SHA-256 of its bytes."""
    return "sha256:" + hashlib.sha256(yaml_bytes).hexdigest()
