"""Python clients of the BSLS capture daemon (bslsd) and of the processing
service (bsls-processd) for automation scripts.

    from bsls_client import CaptureClient
    with CaptureClient.unix("/run/bsls/bslsd.sock") as bsls:
        bsls.set_slide(2)
        capture = bsls.grab("both", session_id="s1", include_frames=True)
        left = capture.frames[0].image          # numpy uint8 array, rows x columns

    from bsls_client import ProcessingClient
    with ProcessingClient.unix("/run/bsls-processd/processd.sock") as service:
        done = service.process_frame(left, "left", calibration=left_yaml, want_surface=True)
        done.files["surface.ply"], done.result.sides[0].q_absolute

Every call carries a deadline; errors raise CaptureError / ProcessingError
with the gRPC status code and the service's message.
"""
from .client import CaptureClient, CaptureError, Capture, Frame, Processing
from .processing import ProcessingClient, ProcessingError, WorkResult, calibration_id

__all__ = ["CaptureClient", "CaptureError", "Capture", "Frame", "Processing",
           "ProcessingClient", "ProcessingError", "WorkResult", "calibration_id"]
