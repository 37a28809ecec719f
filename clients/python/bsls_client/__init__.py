"""Python client of the BSLS capture daemon (bslsd) for automation scripts.

    from bsls_client import CaptureClient
    with CaptureClient.unix("/run/bsls/bslsd.sock") as bsls:
        bsls.set_slide(2)
        capture = bsls.grab("both", session_id="s1", include_frames=True)
        left = capture.frames[0].image          # numpy uint8 array, rows x columns

Every call carries a deadline; errors raise CaptureError with the gRPC status
code and the daemon's message.
"""
from .client import CaptureClient, CaptureError, Capture, Frame

__all__ = ["CaptureClient", "CaptureError", "Capture", "Frame"]
