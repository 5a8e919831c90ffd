#!/usr/bin/env python3
"""The exactness fuzzer finds a planted fault and shrinks it (docs/exactness_fuzzing.md).

The fault is the test-only SHADOWLAB_FAULT_PLANTED_LIT of psv's query (every 61st pixel written
lit), switched on in a copy of the shaders (SHADOWLAB_SHADER_DIR). Fixed seeds: the fuzzer must
find psv wrong, shrink the case to at most 10 triangles, and the shrunk config must fail with the
fault (exit 3: its expectation) and pass on the real shaders (exit 0). Its pieces are checked too:
ddmin finds a minimal subset, the generator is reproducible, the median split is exact.

Usage: test_exactness_fuzz.py SHADOWLAB_BINARY SOURCE_DIR   (ctest runs it)
"""
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

BINARY, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
FUZZ = os.path.join(SOURCE, "scripts", "exactness_fuzz.py")
sys.path.insert(0, os.path.join(SOURCE, "scripts"))
import exactness_fuzz as ef  # noqa: E402


def planted_shaders(folder):
    """A copy of the shaders with psv's planted-lit fault on."""
    shaders = os.path.join(folder, "shaders")
    shutil.copytree(os.path.join(SOURCE, "shaders"), shaders)
    query = os.path.join(shaders, "psv", "query.comp")
    with open(query) as f:
        text = f.read()
    assert "#if SHADOWLAB_FAULT_PLANTED_LIT" in text
    with open(query, "w") as f:
        f.write(text.replace("#if SHADOWLAB_FAULT_PLANTED_LIT", "#if 1"))
    return shaders


class Pieces(unittest.TestCase):
    def test_ddmin_finds_a_minimal_failing_subset(self):
        calls = []

        def fails(s):
            calls.append(len(s))
            return 3 in s and 17 in s
        self.assertEqual(sorted(ef.ddmin(list(range(40)), fails)), [3, 17])
        self.assertLess(len(calls), 100)  # ddmin is O(n log n) here; a broken one is O(n²): 1,600

    def test_the_generator_is_reproducible_and_varied(self):
        self.assertEqual(json.dumps(ef.generate(7)), json.dumps(ef.generate(7)))
        kinds = {ef.generate(s)["light"]["type"] for s in range(40)}
        self.assertEqual(kinds, {"point", "spot", "directional"})

    def test_the_median_split_covers_the_triangle_exactly(self):
        case = {"objects": [{"tris": [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]}]}
        import random
        split = ef.split_along_median(case, random.Random(1))
        halves = split["objects"][0]["tris"]
        self.assertEqual(len(halves), 2)
        self.assertAlmostEqual(sum(ef.area2(t) for t in halves), ef.area2(case["objects"][0]["tris"][0]), places=12)
        # No float midpoint, no split there (the halves would not cover the triangle).
        self.assertIsNone(ef.exact_midpoint([0.0, 1.0, 0.0], [1.0, ef.f32(1 + 2 ** -23), 0.0]))


class RunArguments(unittest.TestCase):
    def test_bad_arguments_and_someone_elses_folder_are_refused(self):
        """Tenth probe: --out overwrote a user's report.json; --only nope and --seconds -5 ran
        nothing and exited 0."""
        with tempfile.TemporaryDirectory() as tmp:
            mine = os.path.join(tmp, "notes")
            os.makedirs(mine)
            with open(os.path.join(mine, "report.json"), "w") as f:
                f.write("my notes")
            for extra in (["--out", mine], ["--out", os.path.join(mine, "report.json")], ["--only", "nope"],
                          ["--seconds", "-5"], ["--cases", "-1"], ["--seconds", "inf", "--cases", "0"]):
                r = subprocess.run([sys.executable, FUZZ, "--binary", BINARY, "run", "--seconds", "5",
                                    "--out", os.path.join(tmp, "o")] + extra, capture_output=True, text=True,
                                   stdin=subprocess.DEVNULL)
                self.assertEqual(r.returncode, 2, (extra, r.stderr))
                self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
            with open(os.path.join(mine, "report.json")) as f:
                self.assertEqual(f.read(), "my notes")
            # Eleventh probe: a missing binary was a traceback and exit 1, a missing replay case a
            # failed case (exit 1), and --seconds inf with --cases 0 ran until killed (above).
            # Fourteenth probe: an --out under a file or empty, and a binary that is not shadowlab,
            # were tracebacks and exit 1.
            for argv in (["--binary", os.path.join(tmp, "nope"), "run", "--seconds", "5"],
                         ["--binary", BINARY, "replay", os.path.join(tmp, "missing.json")],
                         ["--binary", BINARY, "run", "--seconds", "5", "--out", os.path.join(mine, "report.json", "x")],
                         ["--binary", BINARY, "run", "--seconds", "5", "--out", ""],
                         ["--binary", "/bin/true", "run", "--seconds", "5", "--out", os.path.join(tmp, "t")]):
                r = subprocess.run([sys.executable, FUZZ] + argv, capture_output=True, text=True, stdin=subprocess.DEVNULL)
                self.assertEqual(r.returncode, 2, (argv, r.stderr))
                self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)


class SummaryPixels(unittest.TestCase):
    def test_wrong_pixels_are_listed_per_frame_and_located(self):
        """Frame 0 has no lit pixel (the light under the plane): its entry is null, so frame 1's
        wrong pixels stay at index 1 (eighth probe: the list skipped it and the fuzzer cut the
        wrong keyframe)."""
        tri = [[-0.5, 0.2, -0.5], [-0.5, 0.2, 0.5], [0.5, 0.2, -0.5]]
        config = {"name": "pixels", "resolution": [24, 24], "frames": 2, "warmup_frames": 0, "statistics": "none",
                  "scene": {"objects": [{"procedural": "plane", "size": [4, 4]}, {"procedural": "mesh", "vertices": tri}]},
                  "camera": {"position": [0, 3, 4], "target": [0, 0, 0]},
                  "light": {"path": {"keyframes": [{"time": 0, "position": [0.1, -4, 0.1]},
                                                   {"time": 1, "position": [1, 4, 1]}]}},
                  "algorithms": [{"id": "sm", "algorithm": "shadow_map", "params": {"bias_constant": 0.1}}],
                  "output": {"images_at_frames": [], "plots": False}}
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "c.json")
            with open(path, "w") as f:
                json.dump(config, f)
            r = subprocess.run([BINARY, "run", path, "--out", os.path.join(tmp, "out"), "--no-progress"], capture_output=True,
                               text=True, stdin=subprocess.DEVNULL)
            self.assertEqual(r.returncode, 0, r.stderr[-2000:])
            with open(os.path.join(tmp, "out", "summary.json")) as f:
                summary = json.load(f)
            acc = summary["algorithms"]["sm"]["accuracy"]
        # One G-buffer hash per frame; the light moves, the camera does not: the same G-buffer.
        self.assertEqual(len(summary["gbuffer_hash_per_frame"]), 2)
        self.assertEqual(summary["gbuffer_hash_per_frame"][0], summary["gbuffer_hash_per_frame"][1])
        self.assertEqual(len(summary["algorithms"]["sm"]["visibility_hash_per_frame"]), 2)
        self.assertEqual(acc["frames_measured"], 1)
        self.assertEqual(len(acc["per_frame_wrong_pixels"]), 2)
        self.assertIsNone(acc["per_frame_wrong_pixels"][0])
        self.assertEqual(acc["per_frame_wrong_pixels"][1], acc["false_lit_pixels"] + acc["false_shadowed_pixels"])
        # A depth bias of 0.28 units detaches the shadow of a triangle 0.2 above the plane: all of it lit.
        self.assertGreater(acc["false_lit_pixels"], 0)
        px = acc["first_wrong_pixel"]
        self.assertEqual(px["frame"], 1)
        self.assertTrue(0 <= px["x"] < 24 and 0 <= px["y"] < 24)


class PlantedFault(unittest.TestCase):
    def test_a_planted_fault_is_found_and_shrunk_to_a_few_triangles(self):
        with tempfile.TemporaryDirectory() as tmp:
            env = dict(os.environ, SHADOWLAB_SHADER_DIR=planted_shaders(tmp))
            out = os.path.join(tmp, "out")
            r = subprocess.run([sys.executable, FUZZ, "--binary", BINARY, "run", "--seconds", "600", "--cases", "3",
                                "--seed", "11", "--only", "psv", "--relations", "0", "--out", out, "--expect-failure"],
                               env=env, capture_output=True, text=True, stdin=subprocess.DEVNULL)
            self.assertEqual(r.returncode, 0, r.stdout[-3000:] + r.stderr[-2000:])
            with open(os.path.join(out, "report.json")) as f:
                report = json.load(f)
            shrunk = [f for f in report["failures"] if "shrunk" in f]
            self.assertTrue(shrunk)
            for f in shrunk:
                self.assertTrue(f["id"].startswith("psv"))
                self.assertLessEqual(f["triangles"], 10, f)
            case = os.path.join(out, shrunk[0]["shrunk"])
            for shader_env, code in ((env, 3), (dict(os.environ), 0)):
                run = subprocess.run([BINARY, "run", case, "--out", os.path.join(tmp, f"replay{code}"), "--no-progress"],
                                     env=shader_env, capture_output=True, text=True, stdin=subprocess.DEVNULL)
                self.assertEqual(run.returncode, code, run.stderr[-2000:])


class Corpus(unittest.TestCase):
    def test_every_kept_case_holds(self):
        cases = sorted(glob.glob(os.path.join(SOURCE, "tests", "data", "exactness", "*.json")))
        if not cases:
            self.skipTest("no case kept yet")
        r = subprocess.run([sys.executable, FUZZ, "--binary", BINARY, "replay"] + cases, capture_output=True, text=True,
                           stdin=subprocess.DEVNULL)
        self.assertEqual(r.returncode, 0, r.stdout[-4000:])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
