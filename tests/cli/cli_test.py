#!/usr/bin/env python3
"""End-to-end tests of the `bsls` tool: simulate and process as a user runs
them, the exit codes scripts rely on, and bad input (command.h lists the codes).

Usage: cli_test.py PATH_TO_BSLS
"""
import json
import os
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib

BSLS = None

EXIT_OK, EXIT_NOT_PROCESSED, EXIT_USAGE, EXIT_INPUT, EXIT_OUTPUT = 0, 1, 2, 3, 4


def run(*args):
    return subprocess.run([BSLS, *args], capture_output=True, text=True, timeout=120)


def write_png(path, width, height, pixels, colour_type=0, bit_depth=8):
    """Writes a PNG: colour_type 0 = grey, 2 = RGB; pixels row-major bytes."""
    channels = {0: 1, 2: 3}[colour_type]
    stride = width * channels * bit_depth // 8
    raw = b"".join(b"\x00" + pixels[y * stride:(y + 1) * stride] for y in range(height))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def read_png_grey8(path):
    """Reads back an 8-bit grey PNG written by bsls (filter bytes handled)."""
    with open(path, "rb") as f:
        data = f.read()
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length = struct.unpack(">I", data[pos:pos + 4])[0]
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height = struct.unpack(">II", body[:8])
            assert body[8] == 8 and body[9] == 0, "expected 8-bit grey"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    out, prev = bytearray(), bytearray(width)
    for y in range(height):
        ftype = raw[y * (width + 1)]
        line = bytearray(raw[y * (width + 1) + 1:(y + 1) * (width + 1)])
        for x in range(width):
            a = line[x - 1] if x else 0
            b = prev[x]
            c = prev[x - 1] if x else 0
            if ftype == 1:
                line[x] = (line[x] + a) & 255
            elif ftype == 2:
                line[x] = (line[x] + b) & 255
            elif ftype == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pred) & 255
        out += line
        prev = line
    return width, height, bytes(out)


class CliTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.frame = os.path.join(cls.dir.name, "face_left.png")
        cls.truth = os.path.join(cls.dir.name, "face_left_truth.json")
        r = run("simulate", "--surface", "face", "--side", "left", "-o", cls.frame,
                "--truth", cls.truth)
        assert r.returncode == 0, r.stderr

    def path(self, name):
        return os.path.join(self.dir.name, name)

    def test_process_writes_contract_json_and_overlay(self):
        out, overlay = self.path("j.json"), self.path("o.png")
        r = run("process", self.frame, "--side", "left", "--junctions", out, "--overlay", overlay)
        self.assertEqual(r.returncode, EXIT_OK, r.stderr)
        with open(out) as f:
            j = json.load(f)
        self.assertEqual((j["side"], j["width"], j["height"]), ("left", 512, 512))
        self.assertGreater(len(j["junctions"]), 300)
        self.assertTrue({"x", "y", "p", "q", "kind"} <= set(j["junctions"][0]))
        self.assertGreater(len(j["lines"]), 10)
        self.assertGreater(os.path.getsize(overlay), 10000)
        self.assertIn("junctions", r.stdout)

    def test_evaluate_scores_the_decode_against_the_truth(self):
        out = self.path("e.json")
        self.assertEqual(run("process", self.frame, "--side", "left", "--junctions", out).returncode,
                         EXIT_OK)
        r = run("evaluate", out, self.truth, "--json")
        self.assertEqual(r.returncode, EXIT_OK, r.stderr)
        score = json.loads(r.stdout)
        self.assertGreaterEqual(score["recall"], 0.95)
        self.assertEqual(score["wrong_p"], 0)
        self.assertEqual(score["wrong_q"], 0)
        self.assertLessEqual(score["line_rms_px"], 0.15)
        r = run("evaluate", out, self.frame)  # a PNG is no truth file
        self.assertEqual(r.returncode, EXIT_INPUT)
        self.assertIn("not valid JSON", r.stderr)

    def test_json_summary_for_scripts(self):
        r = run("process", self.frame, "--side", "left", "--junctions", self.path("s.json"), "--json")
        self.assertEqual(r.returncode, EXIT_OK, r.stderr)
        summary = json.loads(r.stdout)
        self.assertGreater(summary["junctions"], 300)
        self.assertIn("time_ms", summary)

    def test_missing_file(self):
        r = run("process", self.path("nope.png"), "--side", "left", "--junctions", self.path("x.json"))
        self.assertEqual(r.returncode, EXIT_INPUT)
        self.assertIn("nope.png", r.stderr)
        self.assertIn("no such file", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1)

    def test_empty_and_truncated_files(self):
        empty = self.path("empty.png")
        open(empty, "wb").close()
        r = run("process", empty, "--side", "left", "--junctions", self.path("x.json"))
        self.assertEqual(r.returncode, EXIT_INPUT)
        self.assertIn("empty", r.stderr)
        with open(self.frame, "rb") as f:
            data = f.read()
        cut = self.path("cut.png")
        with open(cut, "wb") as f:
            f.write(data[:len(data) // 3])
        r = run("process", cut, "--side", "left", "--junctions", self.path("x.json"))
        self.assertEqual(r.returncode, EXIT_INPUT, r.stderr)
        self.assertIn("cut.png", r.stderr)
        garbage = self.path("garbage.png")
        with open(garbage, "wb") as f:
            f.write(os.urandom(5000))
        r = run("process", garbage, "--side", "left", "--junctions", self.path("x.json"))
        self.assertEqual(r.returncode, EXIT_INPUT)

    def test_absurd_size(self):
        tiny = self.path("tiny.png")
        write_png(tiny, 4, 4, bytes(16))
        r = run("process", tiny, "--side", "left", "--junctions", self.path("x.json"))
        self.assertEqual(r.returncode, EXIT_INPUT)
        self.assertIn("size", r.stderr)

    def test_colour_and_16_bit_frames_are_converted_and_said(self):
        w, h, grey = read_png_grey8(self.frame)
        rgb = self.path("rgb.png")
        write_png(rgb, w, h, bytes(v for g in grey for v in (g, g, g)), colour_type=2)
        r = run("process", rgb, "--side", "left", "--junctions", self.path("rgb.json"))
        self.assertEqual(r.returncode, EXIT_OK, r.stderr)
        self.assertIn("converted 3-channel 8-bit", r.stderr)
        deep = self.path("deep.png")
        write_png(deep, w, h, b"".join(struct.pack(">H", g * 257) for g in grey), bit_depth=16)
        r = run("process", deep, "--side", "left", "--junctions", self.path("deep.json"))
        self.assertEqual(r.returncode, EXIT_OK, r.stderr)
        self.assertIn("16-bit", r.stderr)
        with open(self.path("deep.json")) as f:
            self.assertGreater(len(json.load(f)["junctions"]), 300)

    def test_black_frame_is_not_processed(self):
        black = self.path("black.png")
        write_png(black, 128, 128, bytes(128 * 128))
        out = self.path("black.json")
        r = run("process", black, "--side", "left", "--junctions", out)
        self.assertEqual(r.returncode, EXIT_NOT_PROCESSED)
        self.assertIn("blank", r.stderr)
        self.assertFalse(os.path.exists(out), "no output for a frame that was not processed")

    def test_wrong_side_has_no_reference_line(self):
        out = self.path("wrong.json")
        r = run("process", self.frame, "--side", "right", "--junctions", out)
        self.assertEqual(r.returncode, EXIT_NOT_PROCESSED, r.stdout)
        self.assertIn("reference line", r.stderr)
        self.assertFalse(os.path.exists(out))

    def test_usage_errors(self):
        self.assertEqual(run("process", self.frame, "--side", "up", "--junctions", "x").returncode,
                         EXIT_USAGE)
        self.assertEqual(run("process", self.frame).returncode, EXIT_USAGE)
        self.assertEqual(run("frobnicate").returncode, EXIT_USAGE)
        self.assertEqual(run("simulate", "--surface", "teapot", "-o", "x.png").returncode, EXIT_USAGE)

    def test_unwritable_output_leaves_nothing_behind(self):
        folder = self.path("missing_folder")
        r = run("process", self.frame, "--side", "left", "--junctions", os.path.join(folder, "j.json"))
        self.assertEqual(r.returncode, EXIT_OUTPUT)
        self.assertIn("missing_folder", r.stderr)
        self.assertFalse(os.path.exists(folder))

    def test_existing_output_is_replaced_whole(self):
        out = self.path("replace.json")
        with open(out, "w") as f:
            f.write("old")
        r = run("process", self.frame, "--side", "left", "--junctions", out)
        self.assertEqual(r.returncode, EXIT_OK, r.stderr)
        with open(out) as f:
            json.load(f)
        leftovers = [n for n in os.listdir(self.dir.name) if n.startswith(".replace.json.tmp")]
        self.assertEqual(leftovers, [])


if __name__ == "__main__":
    BSLS = sys.argv.pop(1)
    unittest.main(verbosity=2)
