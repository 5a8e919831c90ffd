#!/usr/bin/env python3
"""The example CI jobs (examples/ci/github-actions.yml, gitlab-ci.yml) do what they say: their
shell lines between "# ci-begin" and "# ci-end" are the same in both files, and run here, as a
pipeline would, three times in one working folder (a checkout with build/shadowlab and configs/):

  1. on main, with no history yet: the smoke run passes its expectations (exit 0), nothing is
     compared, the run is kept in smoke-history/;
  2. on a branch: the run is compared with main's newest (ci/compare), main's history untouched;
  3. on main again: compared, kept, and the history of main's two runs drawn (ci/history).

Each time the job's exit status is 1 exactly when one of run, compare or history found something
(their own JSON outputs say which), never because a command was misspelt or refused its input.

Usage: test_ci_examples.py SHADOWLAB_BINARY SOURCE_DIR   (ctest runs it)
"""
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

BINARY, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
EXAMPLES = os.path.join(SOURCE, "examples", "ci")


def block(path):
    """The shell lines between the markers, dedented."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    begin, end = text.index("# ci-begin"), text.index("# ci-end")
    start = text.rindex("\n", 0, begin) + 1
    return textwrap.dedent(text[start:end])


class CiExamples(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.script = block(os.path.join(EXAMPLES, "github-actions.yml"))
        cls.work = tempfile.mkdtemp(prefix="shadowlab-ci-")
        os.makedirs(os.path.join(cls.work, "build"))
        os.symlink(BINARY, os.path.join(cls.work, "build", "shadowlab"))
        os.makedirs(os.path.join(cls.work, "configs"))
        with open(os.path.join(SOURCE, "configs", "smoke.json"), encoding="utf-8") as f:
            smoke = json.load(f)
        # The shipped smoke config at a quarter of its pixels and two frames: the commands are
        # under test here, not the machine (this runs the job three times, 9 passes each).
        smoke["resolution"] = [64, 64]
        smoke["frames"] = 2
        smoke["output"] = {"images_at_frames": [1], "plots": False}
        with open(os.path.join(cls.work, "configs", "smoke.json"), "w", encoding="utf-8") as f:
            json.dump(smoke, f)

    def job(self, on_main, commit):
        env = dict(os.environ, ON_MAIN="true" if on_main else "false", COMMIT=commit)
        return subprocess.run(["bash", "-c", self.script], cwd=self.work, env=env, capture_output=True, text=True, timeout=1200)

    def history(self):
        return sorted(os.listdir(os.path.join(self.work, "smoke-history")))

    def read(self, *parts):
        with open(os.path.join(self.work, *parts), encoding="utf-8") as f:
            return json.load(f) if parts[-1].endswith(".json") else f.read()

    def found_something(self):
        """Whether run, compare or history reported a failure in this job's outputs."""
        summary = self.read("ci", "smoke", "summary.json")
        failed = any(not e["passed"] for e in summary.get("expectations", []))
        if os.path.isdir(os.path.join(self.work, "ci", "compare")):
            failed |= self.read("ci", "compare", "compare.json")["regressions"] > 0
        if os.path.isdir(os.path.join(self.work, "ci", "history")):
            failed |= self.read("ci", "history", "history.json")["newest_regressions"] > 0
        return failed

    def test_the_two_files_run_the_same_lines(self):
        self.assertEqual(self.script, block(os.path.join(EXAMPLES, "gitlab-ci.yml")))
        with open(os.path.join(EXAMPLES, "github-actions.yml"), encoding="utf-8") as f:
            self.assertIn("report_paths: ci/**/*.junit.xml", f.read())
        with open(os.path.join(EXAMPLES, "gitlab-ci.yml"), encoding="utf-8") as f:
            text = f.read()
        for junit in ("ci/smoke/expectations.junit.xml", "ci/compare/compare.junit.xml", "ci/history/history.junit.xml"):
            self.assertIn(junit, text, f"gitlab-ci.yml does not publish {junit}")

    def test_three_pipelines(self):
        first = self.job(True, "1" * 40)
        self.assertEqual(first.returncode, 0, first.stderr)
        self.assertTrue(os.path.isfile(os.path.join(self.work, "ci", "smoke", "expectations.junit.xml")))
        self.assertFalse(os.path.exists(os.path.join(self.work, "ci", "compare")), "compared with no earlier run")
        self.assertEqual(len(self.history()), 1)
        self.assertTrue(self.history()[0].endswith("-" + "1" * 10), self.history())

        branch = self.job(False, "2" * 40)
        self.assertNotIn("error:", branch.stderr)
        self.assertTrue(os.path.isfile(os.path.join(self.work, "ci", "compare", "compare.junit.xml")), branch.stderr)
        self.assertEqual(branch.returncode, int(self.found_something()), branch.stderr)
        self.assertEqual(len(self.history()), 1, "a branch wrote main's history")

        again = self.job(True, "3" * 40)
        self.assertNotIn("error:", again.stderr)
        self.assertEqual(len(self.history()), 2)
        for f in ("history.md", "history.html", "history.junit.xml", "history_time.png"):
            self.assertTrue(os.path.isfile(os.path.join(self.work, "ci", "history", f)), f + "\n" + again.stderr)
        self.assertEqual(again.returncode, int(self.found_something()), again.stderr)
        self.assertEqual(len(self.read("ci", "history", "history.json")["runs"]), 2)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
