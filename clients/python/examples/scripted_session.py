#!/usr/bin/python3
"""A scripted capture session: reference slide, then each side's pattern slide
and a grab of that side, then both sides back to back; prints what was stored.

    scripted_session.py --socket /run/bsls/bslsd.sock --session S1 --patient P-0001
"""
import argparse
import sys

from bsls_client import CaptureClient, CaptureError


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--socket", default="/run/bsls/bslsd.sock")
    parser.add_argument("--session", required=True)
    parser.add_argument("--patient", default="")
    args = parser.parse_args()
    try:
        with CaptureClient.unix(args.socket) as bsls:
            print("device:", bsls.status().backend)
            bsls.set_lamp(True)
            stored = []
            for slide, side in ((1, "both"), (2, "left"), (3, "right")):
                state = bsls.set_slide(slide)
                print(f"slide {state.slide} in place")
                capture = bsls.grab(side, session_id=args.session,
                                    patient_reference=args.patient)
                stored.append(capture)
                print(f"  {side}: capture {capture.capture_id}")
            for capture in bsls.captures(session_id=args.session):
                print(capture.capture_id, capture.side, "slide", capture.slide)
    except CaptureError as error:
        print(f"scripted_session: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
