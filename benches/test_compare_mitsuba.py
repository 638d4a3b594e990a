"""Unit tests of the benchmark's own arithmetic and files (no renderer needed):
python3 -m unittest discover -s benches -p 'test_*.py'"""

import math
import struct
import tempfile
import unittest
import zlib
from pathlib import Path

import compare_mitsuba
import exr_read


def exr_bytes(width, height, channels, compression):
    """A single-part scan-line EXR: channels is a list of (name, pixel type, rows of values)."""
    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", t, 0, 1, 1) for n, t, _ in channels) + b"\0"
    header = struct.pack("<II", 20000630, 2)
    header += attribute("channels", "chlist", chlist)
    header += attribute("compression", "compression", bytes([compression]))
    header += attribute("dataWindow", "box2i", struct.pack("<4i", 0, 0, width - 1, height - 1))
    header += attribute("displayWindow", "box2i", struct.pack("<4i", 0, 0, width - 1, height - 1))
    header += attribute("lineOrder", "lineOrder", b"\0")
    header += b"\0"
    lines = 16 if compression == 3 else 1
    blocks = []
    for y0 in range(0, height, lines):
        raw = b""
        for y in range(y0, min(y0 + lines, height)):
            for _, t, rows in channels:
                code = {0: "I", 1: "e", 2: "f"}[t]
                raw += struct.pack(f"<{width}{code}", *rows[y])
        if compression:
            # OpenEXR's ZIP: split even and odd bytes, then a delta predictor, then zlib.
            split = raw[0::2] + raw[1::2]
            predicted = bytearray(split)
            for i in range(len(split) - 1, 0, -1):
                predicted[i] = (split[i] - split[i - 1] + 128 + 256) & 0xFF
            raw = zlib.compress(bytes(predicted))
        blocks.append(struct.pack("<ii", y0, len(raw)) + raw)
    at = len(header) + 8 * len(blocks)
    offsets = []
    for block in blocks:
        offsets.append(at)
        at += len(block)
    return header + struct.pack(f"<{len(offsets)}Q", *offsets) + b"".join(blocks)


class RelMse(unittest.TestCase):
    def test_definition(self):
        image = [1.0, 0.0, 0.5, 9.0, 9.0, 9.0]
        reference = [0.5, 0.0, 0.5, 0.0, 0.0, 0.0]
        # The second pixel is masked out; the first's channels: 0.25/0.26, 0, 0.
        expected = (0.25 / 0.26) / 3
        self.assertAlmostEqual(compare_mitsuba.rel_mse(image, reference, [True, False]), expected, places=12)
        # A uniform error e at reference r: e^2 / (r^2 + 0.01).
        self.assertAlmostEqual(compare_mitsuba.rel_mse([1.1] * 6, [1.0] * 6, [True, True]), 0.01 / 1.01, places=12)

    def test_no_covered_pixel_is_an_error(self):
        with self.assertRaises(ValueError):
            compare_mitsuba.rel_mse([1.0] * 3, [1.0] * 3, [False])

    def test_mean_radiance_counts_covered_pixels_only(self):
        self.assertAlmostEqual(compare_mitsuba.mean_radiance([1, 2, 3, 9, 9, 9, 0, 0, 1], [True, False, True]), 3.5)

    def test_efficiency(self):
        self.assertAlmostEqual(compare_mitsuba.efficiency(0.5, 0.01), 200.0)


class Looks(unittest.TestCase):
    def test_every_material_is_written_as_a_layer_override(self):
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "look.toml"
            compare_mitsuba.write_look(path, compare_mitsuba.MATERIALS["clearcoat"])
            text = path.read_text()
        self.assertIn("[object.layer.set]", text)
        self.assertIn("base_color = [0.3, 0.01, 0.015]", text)
        self.assertIn("clearcoat_gloss = 0.95", text)


class ExrRead(unittest.TestCase):
    def check(self, compression):
        width, height = 5, 19
        floats = [[x * 0.25 + y for x in range(width)] for y in range(height)]
        halves = [[(x - y) * 0.5 for x in range(width)] for y in range(height)]
        ids = [[x + 100 * y for x in range(width)] for y in range(height)]
        data = exr_bytes(width, height, [("A", 1, halves), ("B", 2, floats), ("id", 0, ids)], compression)
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "t.exr"
            path.write_bytes(data)
            w, h, planes = exr_read.read(path)
        self.assertEqual((w, h), (width, height))
        self.assertEqual(list(planes["B"]), [v for row in floats for v in row])
        self.assertEqual(list(planes["A"]), [v for row in halves for v in row])
        self.assertEqual(list(planes["id"]), [v for row in ids for v in row])

    def test_uncompressed(self):
        self.check(0)

    def test_zip_one_line(self):
        self.check(2)

    def test_zip_sixteen_lines(self):
        self.check(3)

    def test_other_files_are_refused_by_name(self):
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "t.exr"
            path.write_bytes(b"not an exr")
            with self.assertRaisesRegex(exr_read.ExrError, "not an OpenEXR file"):
                exr_read.read(path)
            data = bytearray(exr_bytes(1, 1, [("R", 2, [[1.0]])], 0))
            data[data.index(b"compression") + len("compression\0compression\0") + 4] = 4  # PIZ
            path.write_bytes(bytes(data))
            with self.assertRaisesRegex(exr_read.ExrError, "compression 4 is not supported"):
                exr_read.read(path)

    def test_chromaticities_matrix_maps_white_to_white(self):
        try:
            import numpy  # noqa: F401
        except ImportError:
            self.skipTest("numpy is not installed")
        m = compare_mitsuba.rgb_to_xyz(compare_mitsuba.REC709)
        # Rec.709 white (1, 1, 1) is D65: X 0.9505, Y 1, Z 1.089.
        self.assertTrue(all(math.isclose(a, b, rel_tol=1e-3) for a, b in zip(m.sum(axis=1), [0.9505, 1.0, 1.089])))


if __name__ == "__main__":
    unittest.main()
