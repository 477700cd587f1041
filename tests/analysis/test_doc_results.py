"""AnalysisTest: analysis/doc_results.py, the generator of the results in docs/<technique>.md, on
hand-made blocks (no nbsim run): a block rewritten, a stale one named, missing markers and bad
input refused. Run: /usr/bin/python3 -m unittest discover -s tests/analysis -v
"""
import json
import os
import subprocess
import sys
import tempfile
import types
import unittest
from pathlib import Path

sys.dont_write_bytecode = True
HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
SCRIPT = ROOT / "analysis" / "doc_results.py"
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
sys.path.insert(0, str(ROOT / "analysis"))
import doc_results  # noqa: E402


FAKE_PAGE = "fake" + ".md"  # a page made for the test, in a temporary folder


def fake_module():
    block = doc_results.Block("table", [["trace", "info", "x.nbt", "--json"]],
                              lambda outputs: f"| frames |\n|---:|\n| {outputs[0]['frames']} |")
    return types.SimpleNamespace(PAGE=FAKE_PAGE, BLOCKS=[block])


class DocResultsTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.docs = Path(self.tmp.name)
        self.page = self.docs / FAKE_PAGE
        self.page.write_text("# Fake\n\nBefore.\n\n" + doc_results.begin_marker("fake", "table") + "\nold\n" +
                             doc_results.end_marker("fake", "table") + "\n\nAfter.\n", encoding="utf-8")
        self.saved = doc_results.technique_modules
        doc_results.technique_modules = lambda: [("fake", fake_module())]

    def tearDown(self):
        doc_results.technique_modules = self.saved
        self.tmp.cleanup()

    def test_update_writes_the_commands_and_the_rendered_block(self):
        stale = doc_results.write_or_check({"fake": {"table": [{"frames": 7}]}}, self.docs, check=False)
        self.assertEqual(stale, [f"fake/table ({self.page})"])
        text = self.page.read_text(encoding="utf-8")
        self.assertIn("```sh\nnbsim trace info x.nbt --json\n```", text)
        self.assertIn("| 7 |", text)
        self.assertTrue(text.startswith("# Fake\n\nBefore.") and text.endswith("After.\n"))
        # Current now: a second check finds nothing stale and leaves the file alone.
        self.assertEqual(doc_results.write_or_check({"fake": {"table": [{"frames": 7}]}}, self.docs, check=True), [])

    def test_check_names_a_stale_block_and_writes_nothing(self):
        doc_results.write_or_check({"fake": {"table": [{"frames": 7}]}}, self.docs, check=False)
        before = self.page.read_text(encoding="utf-8")
        stale = doc_results.write_or_check({"fake": {"table": [{"frames": 8}]}}, self.docs, check=True)
        self.assertEqual(stale, [f"fake/table ({self.page})"])
        self.assertEqual(self.page.read_text(encoding="utf-8"), before)

    def test_missing_markers_are_refused(self):
        self.page.write_text("# Fake\n", encoding="utf-8")
        with self.assertRaisesRegex(ValueError, "marker lines of fake/table"):
            doc_results.write_or_check({"fake": {"table": [{"frames": 7}]}}, self.docs, check=True)

    def test_outputs_that_do_not_fit_the_block_are_refused(self):
        with self.assertRaisesRegex(ValueError, "1 commands and 0 files: collect again"):
            doc_results.write_or_check({"fake": {"table": [1, 2]}}, self.docs, check=True)
        with self.assertRaisesRegex(ValueError, "no such block"):
            doc_results.write_or_check({"fake": {"other": []}}, self.docs, check=True)
        with self.assertRaisesRegex(ValueError, "technique 'nope', which has no "):
            doc_results.write_or_check({"nope": {}}, self.docs, check=True)


class DocResultsCliTest(unittest.TestCase):
    def run_script(self, *args, stdin=""):
        return subprocess.run([PYTHON, str(SCRIPT), *args], input=stdin, capture_output=True, text=True,
                              env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))

    def test_bad_input_exits_2_with_a_message(self):
        p = self.run_script("--check", str(ROOT / "docs"), stdin="not json")
        self.assertEqual(p.returncode, 2)
        self.assertIn("doc_results:", p.stderr)
        p = self.run_script("--check", str(ROOT / "docs"), stdin="[1]")
        self.assertEqual(p.returncode, 2)
        self.assertIn("not the JSON that --collect prints", p.stderr)
        p = self.run_script("--frobnicate")
        self.assertEqual(p.returncode, 2)
        p = self.run_script("--collect", "--only", "no_such_technique", "--nbsim", "/bin/false")
        self.assertEqual(p.returncode, 2)
        self.assertIn("no such technique or block", p.stderr)

    def test_every_technique_page_holds_its_blocks(self):
        # Each declared block has its markers in its page once, in order (what --update needs).
        for name, module in doc_results.technique_modules():
            for block in module.BLOCKS:
                text = (ROOT / "docs" / (block.page or module.PAGE)).read_text(encoding="utf-8")
                begin, end = doc_results.begin_marker(name, block.name), doc_results.end_marker(name, block.name)
                self.assertEqual((text.count(begin), text.count(end)), (1, 1), f"{name}/{block.name}")
                self.assertLess(text.index(begin), text.index(end))

    def test_list_prints_every_block(self):
        p = self.run_script("--list")
        self.assertEqual(p.returncode, 0, p.stderr)
        for name, module in doc_results.technique_modules():
            for block in module.BLOCKS:
                self.assertIn(f"{name}/{block.name} (docs/{block.page or module.PAGE})", p.stdout)


if __name__ == "__main__":
    unittest.main()
