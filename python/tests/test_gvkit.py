"""The gvkit Python module end to end: numpy frames encoded into .gvid streams and read back
(lossless exactly, lossy within its quality target), profiles, tune keys, stats, errors that name
the file, a legacy 1.x stream, and the plot example. Run by ctest (python_module_test) with the
built module on PYTHONPATH."""
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import gvkit

SOURCE_DIR = pathlib.Path(os.environ.get("GVKIT_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))


def surface_video(frames=4, size=48):
    """A smooth bump (mm) on an elliptic domain, moving and breathing: (N, H, W, 3), (H, W)."""
    y, x = np.mgrid[0:size, 0:size].astype(np.float64)
    u, v = (x - size / 2) / (size / 2), (y - size / 2) / (size / 2)
    valid = u * u / 0.9 + v * v / 0.7 < 1.0
    xyz = np.empty((frames, size, size, 3), np.float32)
    for f in range(frames):
        s = 1.0 + 0.02 * f
        xyz[f, ..., 0] = 100.0 * u * s + 0.75 * f
        xyz[f, ..., 1] = 120.0 * v * s + 0.375 * f
        xyz[f, ..., 2] = 600.0 + 40.0 * np.exp(-(u * u + v * v) * 2.0) * s + 3.0 * np.sin(3 * u + f)
    return xyz, valid


class EncodeAndRead(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.dir.name, "v.gvid")
        self.xyz, self.valid = surface_video()

    def tearDown(self):
        self.dir.cleanup()

    def test_lossless_round_trip_is_exact_to_the_quantization(self):
        out = gvkit.encode(self.path, self.xyz, self.valid, lossless=True, preset="fast")
        self.assertEqual(out["profile"], "lossless")
        self.assertEqual(out["format"], "2.0")
        r = gvkit.open(self.path)
        info = r.info
        self.assertEqual((info["width"], info["height"], info["frames"]), (48, 48, 4))
        self.assertEqual((info["format"], info["profile"], info["legacy"]), ("2.0", "lossless", False))
        self.assertEqual(len(r), 4)
        xyz, valid = r.read_all()
        self.assertEqual(xyz.shape, (4, 48, 48, 3))
        self.assertEqual(xyz.dtype, np.float32)
        np.testing.assert_array_equal(valid, self.valid)
        # Within half a quantization step per axis of the input, on every domain pixel.
        error = np.abs(xyz[:, valid] - self.xyz[:, valid]).max()
        self.assertLessEqual(error, 0.5 * info["step_mm"] + 1e-4)
        self.assertLess(out["max_error_mm"], info["step_mm"])  # point error: sqrt(3) / 2 steps
        # One frame, negative index, iteration: the same samples.
        first, first_valid = r.read(0)
        np.testing.assert_array_equal(first, xyz[0])
        np.testing.assert_array_equal(r.read(-1)[0], xyz[3])
        self.assertEqual(sum(1 for _ in r), 4)
        with self.assertRaises(IndexError):
            r.read(4)

    def test_quality_target_and_stats(self):
        out = gvkit.encode(self.path, self.xyz, self.valid, quality=60.0, preset="fast")
        self.assertEqual(out["profile"], "main")
        self.assertTrue(np.all(out["psnr_db"] >= 60.0), out["psnr_db"])
        stats = gvkit.open(self.path).stats()
        np.testing.assert_array_equal(stats["bits"], out["bits"])
        np.testing.assert_array_equal(stats["type"], out["type"])
        self.assertEqual(list(stats["type"][:3]), ["I", "B", "P"])
        # The file: the header, the packets, then the index (20 bytes a frame) and trailer.
        index_bytes = os.path.getsize(self.path) - out["file_bytes"]
        self.assertEqual(index_bytes, 4 + 4 + 20 * 4 + 4 + 12)
        decoded, valid = gvkit.open(self.path).read_all()
        diagonal = gvkit.open(self.path).info["box_diagonal_mm"]
        rms = np.sqrt(np.mean(np.sum((decoded[:, valid] - self.xyz[:, valid]) ** 2, axis=-1)))
        self.assertGreaterEqual(20 * np.log10(diagonal / rms), 60.0)

    def test_profiles_and_tune_keys(self):
        out = gvkit.encode(self.path, self.xyz, self.valid, qp=12, profile="intra", preset="fast")
        self.assertEqual(out["profile"], "intra")
        r = gvkit.open(self.path)
        self.assertEqual(r.info["profile"], "intra")
        self.assertTrue(all(t == "I" for t in r.stats()["type"]))
        out = gvkit.encode(self.path, self.xyz, self.valid, qp=6, preset="fast",
                           tune={"bframes": 0, "merge": False, "plane-qp-offsets": (0, 0, 2)})
        self.assertEqual(list(out["type"]), ["I", "P", "P", "P"])
        names = [k[0] for k in gvkit.tune_keys]
        for key in ("merge", "td16", "quadratic-intra", "deblock", "refs", "resolution"):
            self.assertIn(key, names)

    def test_bad_arguments_raise_value_errors_naming_them(self):
        with self.assertRaisesRegex(ValueError, "tune merge=maybe"):
            gvkit.encode(self.path, self.xyz, self.valid, tune={"merge": "maybe"})
        with self.assertRaisesRegex(ValueError, "unknown key"):
            gvkit.encode(self.path, self.xyz, self.valid, tune={"frobnicate": 1})
        with self.assertRaisesRegex(ValueError, "exclude each other"):
            gvkit.encode(self.path, self.xyz, self.valid, quality=60.0, lossless=True)
        with self.assertRaisesRegex(ValueError, "v.gvid: qp 99 out of range"):
            gvkit.encode(self.path, self.xyz, self.valid, qp=99)
        with self.assertRaisesRegex(ValueError, "profile 'high' unknown"):
            gvkit.encode(self.path, self.xyz, self.valid, profile="high")
        with self.assertRaisesRegex(ValueError, r"xyz: shape \(48, 48\)"):
            gvkit.encode(self.path, self.xyz[0, ..., 0], self.valid)
        with self.assertRaisesRegex(ValueError, "valid: shape"):
            gvkit.encode(self.path, self.xyz, self.valid[:10])
        holes = self.xyz.copy()
        holes[1, 24, 24, 2] = np.nan  # inside the domain
        with self.assertRaisesRegex(ValueError, "v.gvid: frame 1: .*non-finite"):
            gvkit.encode(self.path, holes, self.valid)
        self.assertFalse(os.path.exists(self.path))


class Streams(unittest.TestCase):
    def test_missing_and_damaged_files_raise_naming_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            missing = os.path.join(d, "missing.gvid")
            with self.assertRaisesRegex(FileNotFoundError, "missing.gvid"):
                gvkit.open(missing)
            garbage = os.path.join(d, "garbage.gvid")
            pathlib.Path(garbage).write_bytes(b"GVID but not really")
            with self.assertRaisesRegex(RuntimeError, "garbage.gvid: header"):
                gvkit.open(garbage)

    def test_golden_and_legacy_streams(self):
        r = gvkit.open(str(SOURCE_DIR / "tests/golden/v2/main_fast_qp6_ibpbp_texture_48.gvid"))
        self.assertTrue(r.info["has_texture"])
        xyz, valid, texture = r.read(2, texture=True)
        self.assertEqual(texture.shape, (48, 48))
        self.assertTrue(0.0 <= texture.min() and texture.max() <= 1.0)
        legacy = gvkit.open(str(SOURCE_DIR / "tests/golden/v1/analytic_temporal_slow_qp6_ibpbp_v1_9_48.gvid"))
        self.assertEqual((legacy.info["format"], legacy.info["legacy"], legacy.info["profile"]),
                         ("1.9", True, None))
        xyz, valid = legacy.read_all()
        self.assertEqual(xyz.shape, (5, 48, 48, 3))
        self.assertTrue(np.all(np.isfinite(xyz[:, valid])))

    def test_plot_example_writes_a_png(self):
        with tempfile.TemporaryDirectory() as d:
            png = os.path.join(d, "bits.png")
            script = SOURCE_DIR / "python/examples/plot_bits.py"
            stream = SOURCE_DIR / "tests/golden/v2/main_fast_qp6_ibpbp_texture_48.gvid"
            done = subprocess.run([sys.executable, str(script), str(stream), "-o", png],
                                  capture_output=True, text=True, env=dict(os.environ))
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertTrue(pathlib.Path(png).read_bytes().startswith(b"\x89PNG"))


if __name__ == "__main__":
    unittest.main()
