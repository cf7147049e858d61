"""docs/answers.md is what scripts/answers.py makes of the whole-data run kept in docs/: every
table of the page regenerated from the CSV files named in its sources block, and the figures
written; a table edited by hand, or a CSV file changed without the page, fails here."""

import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
RUN = ROOT / "docs" / "answers-data" / "run"
# The command of docs/answers.md ("Where the numbers come from"): the one run of answers.sh.
SOURCES = [RUN / "study", RUN / "dupuy-jakob"]


def run_answers(tmp_path, page):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "answers.py"), "--out", str(tmp_path / "out"),
         "--page", str(page), "--factored", "docs/answers-data/run/factored.csv"] +
        [str(d.relative_to(ROOT)) for d in SOURCES],  # as the page names them
        capture_output=True, text=True, cwd=ROOT)


def test_the_page_is_what_the_script_makes_of_the_kept_runs(tmp_path):
    page = tmp_path / "answers.md"
    shutil.copy(ROOT / "docs" / "answers.md", page)
    r = run_answers(tmp_path, page)
    assert r.returncode == 0, r.stderr
    assert page.read_text() == (ROOT / "docs" / "answers.md").read_text()
    for use in ("compactness", "interpolation", "acquisition", "fitting", "sampling", "factored"):
        assert (tmp_path / "out" / f"answers-{use}.png").stat().st_size > 10000
        assert f"answers-data/answers-{use}.png" in page.read_text()


def test_a_number_edited_by_hand_is_restored(tmp_path):
    page = tmp_path / "answers.md"
    text = (ROOT / "docs" / "answers.md").read_text()
    edited = text.replace("| all | 174 | **0.0961** |", "| all | 174 | **0.0861** |")
    assert edited != text
    page.write_text(edited)
    assert run_answers(tmp_path, page).returncode == 0
    assert page.read_text() == text


def test_a_page_without_its_blocks_is_an_error(tmp_path):
    page = tmp_path / "answers.md"
    page.write_text("# no blocks\n")
    r = run_answers(tmp_path, page)
    assert r.returncode != 0
    assert "no block <!-- answers:" in r.stderr
    assert page.read_text() == "# no blocks\n"
