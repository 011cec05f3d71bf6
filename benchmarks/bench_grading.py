"""Grading speed: 100 submissions of notebook 01 through the grade tool, on every core.

The submissions are made from the worked notebook and the student edition
(tests/grading_submissions.py): in turn the worked notebook itself, the student edition
with every task worked, with two tasks wrong, and untouched. Prints the wall time and
submissions per minute (target: 100 in at most 10 minutes on the 2-core machine), and
checks every submission got its points.

``python benchmarks/bench_grading.py [N] [--jobs J]``
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import tempfile
import time
from pathlib import Path

import nbformat

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from grading_submissions import (
    NAME,
    WORKED,
    edition,
    filled,
    out_of_order,
    wrong_science,
)

from lqe_helpers.grading.grade import grade_all

#: The kinds of submission, in turn, with the automatic points each must get.
KINDS = (("worked", lambda: WORKED.read_text(encoding="utf-8"), "9"),
         ("filled", lambda: nbformat.writes(filled(edition())), "9"),
         ("wrong", lambda: nbformat.writes(wrong_science(edition())), "0"),
         ("untouched", lambda: nbformat.writes(out_of_order(edition())), "0"))


def main() -> None:
    """Make the submissions, grade them, print the speed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int, nargs="?", default=100)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    texts = {kind: make() for kind, make, _ in KINDS}
    with tempfile.TemporaryDirectory() as folder:
        submissions, out = Path(folder) / "submissions", Path(folder) / "grades"
        expected = {}
        for i in range(args.n):
            kind, _, points = KINDS[i % len(KINDS)]
            student = f"student{i:03d}-{kind}"
            (submissions / student).mkdir(parents=True)
            (submissions / student / NAME).write_text(texts[kind], encoding="utf-8")
            expected[student] = points
        start = time.monotonic()
        table, graded, _ = grade_all(submissions, out, WORKED.parent, jobs=args.jobs,
                                     cell_timeout=60, notebook_timeout=600)
        seconds = time.monotonic() - start
        with table.open(encoding="utf-8") as file:
            got = {row["student"]: row["automatic points"] for row in csv.DictReader(file)}
    wrong = {student for student in expected if got.get(student) != expected[student]}
    print(f"graded {graded} submissions of {NAME} on {args.jobs} jobs in {seconds:.0f} s: "
          f"{60 * graded / seconds:.1f} submissions/minute "
          f"({'all points as expected' if not wrong else f'WRONG POINTS: {sorted(wrong)}'})")
    if wrong:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
