#!/usr/bin/python3
"""A scripted capture session: lamp on, the left brick slide in place, a grab of
both sides (the daemon puts each side's slide in place for its frame), then
waits for the daemon's processing service to reconstruct it and writes the
surface, the reports and the sealed record into a folder; with --processd, also
measures the surface there (heights and a distance, world mm) into
measurements.json and measurements.txt.

    scripted_session.py --socket /run/bsls/bslsd.sock --session S1 --patient P-0001 \\
        --out session/ [--processd unix:/run/bsls-processd/processd.sock]
"""
import argparse
import json
import os
import sys

from bsls_client import CaptureClient, CaptureError, ProcessingClient, ProcessingError


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--socket", default="/run/bsls/bslsd.sock", help="bslsd's Unix socket")
    parser.add_argument("--session", required=True)
    parser.add_argument("--patient", default="")
    parser.add_argument("--out", required=True, help="folder for the results")
    parser.add_argument("--processd", default="",
                        help="a processing service (unix:PATH or loopback HOST:PORT) to measure on")
    parser.add_argument("--timeout", type=float, default=600.0,
                        help="seconds to wait for the reconstruction")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    try:
        with CaptureClient.unix(args.socket) as bsls:
            print("device:", bsls.status().backend)
            bsls.set_lamp(True)
            state = bsls.set_slide(2)
            print(f"slide {state.slide} in place")
            capture = bsls.grab("both", session_id=args.session, patient_reference=args.patient)
            print(f"grabbed both sides: capture {capture.capture_id}")
            done = bsls.wait_processed(capture.capture_id, timeout=args.timeout)
            if done.processing.state != "done":
                print(f"scripted_session: capture {capture.capture_id} was not processed: "
                      f"{done.processing.state} {done.processing.last_error}", file=sys.stderr)
                return 1
            print(f"processed by {done.processing.replica}: {', '.join(done.processing.files)}")
            files = bsls.results(capture.capture_id)
            for name, data in files.items():
                with open(os.path.join(args.out, name), "wb") as out:
                    out.write(data)
            print(f"wrote {len(files)} files to {args.out}")
        if args.processd:
            target = args.processd
            client = (ProcessingClient.unix(target) if target.startswith("unix:")
                      else ProcessingClient.loopback(target))
            with client as service:
                # World mm (contracts section 3): the simulated face's midline is
                # near x = 22.75 mm; two heights and a distance across the face.
                plan = {"heights": [(22.75, -22.75), (0.0, 0.0)],
                        "distances": [((0.0, -20.0), (45.0, -20.0))]}
                measured = service.measure(files["surface.ply"], plan, tag=capture.capture_id)
                report = measured.files["measurements.json"]
                with open(os.path.join(args.out, "measurements.json"), "wb") as out:
                    out.write(report)
                table = json.loads(report)["table"]
                with open(os.path.join(args.out, "measurements.txt"), "w") as out:
                    out.write(table)
                print(table, end="")
    except (CaptureError, ProcessingError) as error:
        print(f"scripted_session: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
