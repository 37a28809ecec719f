"""CaptureClient: the capture daemon's API (proto/bsls/v1/capture.proto) in Python."""
from __future__ import annotations

import dataclasses
import hashlib
import time
from typing import Dict, Iterator, List, Optional

import grpc
import numpy as np

from bsls.v1 import capture_pb2 as pb
from bsls.v1 import capture_pb2_grpc as pb_grpc

_SIDES = {"left": pb.GRAB_SIDE_LEFT, "right": pb.GRAB_SIDE_RIGHT, "both": pb.GRAB_SIDE_BOTH}
_CAMERAS = {"left": pb.CAMERA_LEFT, "right": pb.CAMERA_RIGHT, "third": pb.CAMERA_THIRD}
_CAMERA_NAMES = {v: k for k, v in _CAMERAS.items()}


class CaptureError(Exception):
    """A call the daemon refused or could not complete: `code` is the grpc.StatusCode."""

    def __init__(self, method: str, error: Optional[grpc.RpcError],
                 code: grpc.StatusCode = grpc.StatusCode.DATA_LOSS, details: str = ""):
        self.code = error.code() if error is not None else code
        self.details = error.details() if error is not None else details
        super().__init__(f"{method}: {self.code.name}: {self.details}")

    @staticmethod
    def local(method: str, details: str,
              code: grpc.StatusCode = grpc.StatusCode.DATA_LOSS) -> "CaptureError":
        """An error found on this side (a damaged reply, a wait that timed out)."""
        return CaptureError(method, None, code, details)


@dataclasses.dataclass
class Frame:
    """One grey frame: `image` is a (height, width) uint8 array (empty in listings)."""
    camera: str
    width: int
    height: int
    gain: int
    sha256: str
    image: Optional[np.ndarray]

    @staticmethod
    def from_proto(frame: pb.Frame) -> "Frame":
        image = None
        if frame.pixels:
            rows = np.frombuffer(frame.pixels, dtype=np.uint8).reshape(frame.height, frame.stride)
            image = rows[:, : frame.width].copy()
        return Frame(_CAMERA_NAMES.get(frame.camera, str(frame.camera)), frame.width,
                     frame.height, frame.gain, frame.sha256, image)

    def verify(self) -> bool:
        """True when the pixels hash to the SHA-256 the daemon stored."""
        return self.image is not None and \
            hashlib.sha256(np.ascontiguousarray(self.image).tobytes()).hexdigest() == self.sha256


@dataclasses.dataclass
class Capture:
    """A stored capture's metadata and frames."""
    capture_id: str
    session_id: str
    patient_reference: str
    side: str
    slide: int
    requested_by: str
    frames: List[Frame]
    processing: "Processing"

    @staticmethod
    def from_proto(info: pb.CaptureInfo) -> "Capture":
        side = {v: k for k, v in _SIDES.items()}.get(info.side, str(info.side))
        return Capture(info.capture_id, info.session_id, info.patient_reference, side,
                       info.slide, info.requested_by, [Frame.from_proto(f) for f in info.frames],
                       Processing.from_proto(info.processing))


_STATES = {pb.ProcessingStatus.STATE_PENDING: "pending", pb.ProcessingStatus.STATE_DONE: "done",
           pb.ProcessingStatus.STATE_FAILED: "failed",
           pb.ProcessingStatus.STATE_DISABLED: "disabled"}


@dataclasses.dataclass
class Processing:
    """Where a capture is in the daemon's processing queue: state is "pending",
    "done", "failed" or "disabled" (no processing service configured)."""
    state: str
    attempts: int
    last_error: str
    replica: str
    files: List[str]
    record_sha256: str

    @staticmethod
    def from_proto(status: pb.ProcessingStatus) -> "Processing":
        return Processing(_STATES.get(status.state, "unknown"), status.attempts,
                          status.last_error, status.replica, list(status.files),
                          status.record_sha256)


class CaptureClient:
    """A connection to bslsd; every call has a deadline (`timeout` seconds)."""

    def __init__(self, channel: grpc.Channel, timeout: float = 30.0):
        self._channel = channel
        self._stub = pb_grpc.CaptureDaemonStub(channel)
        self.timeout = timeout

    @classmethod
    def unix(cls, socket_path: str, timeout: float = 30.0) -> "CaptureClient":
        """Connects to the daemon's Unix socket (the caller's uid decides its role)."""
        return cls(grpc.insecure_channel(f"unix:{socket_path}"), timeout)

    @classmethod
    def tcp(cls, address: str, ca: bytes, certificate: bytes, key: bytes,
            timeout: float = 30.0) -> "CaptureClient":
        """Connects over TCP with mutual TLS (PEM bytes; the certificate decides the role)."""
        credentials = grpc.ssl_channel_credentials(ca, key, certificate)
        return cls(grpc.secure_channel(address, credentials), timeout)

    def close(self) -> None:
        self._channel.close()

    def __enter__(self) -> "CaptureClient":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _call(self, method: str, request, timeout: Optional[float] = None):
        try:
            return getattr(self._stub, method)(request, timeout=timeout or self.timeout)
        except grpc.RpcError as error:
            raise CaptureError(method, error) from None

    def status(self) -> pb.DeviceStatus:
        """The device, slide controller and store as they are now."""
        return self._call("GetStatus", pb.GetStatusRequest())

    def select_camera(self, camera: str) -> pb.DeviceStatus:
        """Selects "left", "right" or "third" for previews and single-side grabs."""
        return self._call("SelectCamera", pb.SelectCameraRequest(camera=_CAMERAS.get(camera, -1)))

    def set_gain(self, gain: int) -> pb.DeviceStatus:
        """Sets the manual gain (inside status().gain_range)."""
        return self._call("SetGain", pb.SetGainRequest(gain=gain))

    def grab(self, side: str = "both", session_id: str = "", patient_reference: str = "",
             include_frames: bool = False) -> Capture:
        """Grabs "left", "right" or "both"; returns once the capture is durable."""
        request = pb.GrabRequest(side=_SIDES.get(side, 0), session_id=session_id,
                                 patient_reference=patient_reference,
                                 include_frames=include_frames)
        return Capture.from_proto(self._call("Grab", request).capture)

    def captures(self, session_id: str = "", patient_reference: str = "") -> Iterator[Capture]:
        """Every stored capture matching the filter, oldest first (page by page)."""
        token = ""
        while True:
            page = self._call("ListCaptures", pb.ListCapturesRequest(
                session_id=session_id, patient_reference=patient_reference, page_token=token))
            for info in page.captures:
                yield Capture.from_proto(info)
            token = page.next_page_token
            if not token:
                return

    def capture(self, capture_id: str) -> Capture:
        """One stored capture with its frames."""
        return Capture.from_proto(self._call("GetCapture", pb.GetCaptureRequest(capture_id=capture_id)))

    def results(self, capture_id: str, name: str = "") -> Dict[str, bytes]:
        """The stored processing results of a capture (or only `name`), each
        checked against the SHA-256 the daemon sent with it."""
        request = pb.GetCaptureResultRequest(capture_id=capture_id, name=name)
        files: Dict[str, bytearray] = {}
        try:
            for chunk in self._stub.GetCaptureResult(request, timeout=self.timeout):
                data = files.setdefault(chunk.name, bytearray())
                if chunk.offset != len(data):
                    raise CaptureError.local("GetCaptureResult", f"{chunk.name}: chunk out of order")
                data += chunk.data
                if chunk.last and hashlib.sha256(data).hexdigest() != chunk.sha256:
                    raise CaptureError.local("GetCaptureResult", f"{chunk.name}: SHA-256 mismatch")
        except grpc.RpcError as error:
            raise CaptureError("GetCaptureResult", error) from None
        return {name: bytes(data) for name, data in files.items()}

    def wait_processed(self, capture_id: str, timeout: float = 300.0,
                       poll: float = 0.25) -> Capture:
        """Waits until the capture is no longer pending (done, failed or
        disabled) and returns it; CaptureError DEADLINE_EXCEEDED after `timeout`."""
        deadline = time.monotonic() + timeout
        while True:
            capture = Capture.from_proto(self._call(
                "GetCapture", pb.GetCaptureRequest(capture_id=capture_id)))
            if capture.processing.state != "pending":
                return capture
            if time.monotonic() > deadline:
                raise CaptureError.local(
                    "wait_processed", f"capture {capture_id} still pending after {timeout} s "
                    f"({capture.processing.attempts} attempts: {capture.processing.last_error})",
                    grpc.StatusCode.DEADLINE_EXCEEDED)
            time.sleep(poll)

    def delete(self, capture_id: str) -> None:
        """Deletes a stored capture (admin role)."""
        self._call("DeleteCapture", pb.DeleteCaptureRequest(capture_id=capture_id))

    def slide_state(self) -> pb.SlideState:
        return self._call("GetSlideState", pb.GetSlideStateRequest())

    def set_slide(self, slide: int) -> pb.SlideState:
        """Puts slide 1 (reference), 2 (left) or 3 (right) in place; returns when confirmed."""
        return self._call("SetSlide", pb.SetSlideRequest(slide=slide))

    def set_focus(self, steps: int) -> pb.SlideState:
        return self._call("SetFocus", pb.SetFocusRequest(steps=steps))

    def set_lamp(self, on: bool) -> pb.SlideState:
        return self._call("SetLamp", pb.SetLampRequest(on=on))

    def preview(self, frames: int, camera: str = "", timeout: Optional[float] = None
                ) -> Iterator[Frame]:
        """Up to `frames` live frames of the selected (or named) camera."""
        request = pb.PreviewRequest(camera=_CAMERAS.get(camera, 0) if camera else 0)
        stream = self._stub.StreamPreview(request, timeout=timeout or self.timeout)
        try:
            for count, message in enumerate(stream, start=1):
                yield Frame.from_proto(message.frame)
                if count >= frames:
                    break
        except grpc.RpcError as error:
            raise CaptureError("StreamPreview", error) from None
        finally:
            stream.cancel()

    def events(self, timeout: Optional[float] = None) -> Iterator[pb.Event]:
        """Daemon events until `timeout` seconds pass (or the caller stops iterating)."""
        stream = self._stub.WatchEvents(pb.WatchEventsRequest(), timeout=timeout or self.timeout)
        try:
            yield from stream
        except grpc.RpcError as error:
            if error.code() != grpc.StatusCode.DEADLINE_EXCEEDED:
                raise CaptureError("WatchEvents", error) from None
        finally:
            stream.cancel()
