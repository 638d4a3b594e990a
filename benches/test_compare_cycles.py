"""Unit tests of compare_cycles.py's measures (no Blender or renderer needed):
python3 -m unittest discover -s benches -p 'test_*.py'"""

import json
import struct
import unittest

import compare_cycles


def from_bits(bits):
    return struct.unpack("<f", struct.pack("<I", bits))[0]


class Cryptomatte(unittest.TestCase):
    LAYER = "ViewLayer.CryptoObject"

    def test_ids_are_hashes_with_the_exponent_kept_inside_its_range(self):
        # A name whose hash has exponent 0 is stored with exponent 1; one with 255, with 254.
        manifest = {"Low": "00000005", "High": "ff800007", "Plain": "3f800000"}
        low, high, plain = from_bits(0x00800005), from_bits(0xFF000007), 1.0
        planes = {
            # Two pixels, two ranks: pixel 0 is 0.75 Low (split over both ranks) and 0.25 High;
            # pixel 1 is all Plain.
            f"{self.LAYER}00.r": [low, plain],
            f"{self.LAYER}00.g": [0.5, 1.0],
            f"{self.LAYER}00.b": [high, 0.0],
            f"{self.LAYER}00.a": [0.25, 0.0],
            f"{self.LAYER}01.r": [low, 0.0],
            f"{self.LAYER}01.g": [0.25, 0.0],
            f"{self.LAYER}01.b": [0.0, 0.0],
            f"{self.LAYER}01.a": [0.0, 0.0],
        }
        attributes = {
            "cryptomatte/abc1234/name": self.LAYER,
            "cryptomatte/abc1234/manifest": json.dumps(manifest),
            "cryptomatte/fff0000/name": "ViewLayer.CryptoMaterial",
        }
        coverage = compare_cycles.cryptomatte(planes, attributes, self.LAYER, 2)
        self.assertEqual(coverage, {"Low": [0.75, 0.0], "High": [0.25, 0.0], "Plain": [0.0, 1.0]})


class Regions(unittest.TestCase):
    def test_inside_needs_the_whole_neighbourhood_and_no_border(self):
        # 5x4, covered but for the pixel at (3, 2): of the six pixels off the border, only
        # (1, 1) and (1, 2) have it outside their 3x3 neighbourhood.
        coverage = [1.0] * 20
        coverage[2 * 5 + 3] = 0.5
        self.assertEqual(compare_cycles.inside(coverage, 5, 4), [1 * 5 + 1, 2 * 5 + 1])

    def test_bias_and_error(self):
        grey = lambda v: [v, v, v]  # noqa: E731
        ours = grey(1.1) + grey(0.45) + grey(7.0)
        theirs = grey(1.0) + grey(0.5) + grey(0.0)
        bias, error = compare_cycles.bias_and_error(ours, theirs, [0, 1])
        self.assertAlmostEqual(bias, 1.55 / 1.5 - 1.0, places=6)
        self.assertAlmostEqual(error, (0.1 + 0.1) / 2, places=6)
        with self.assertRaises(ValueError):
            compare_cycles.bias_and_error(ours, theirs, [])


if __name__ == "__main__":
    unittest.main()
