"""nbgrader's ``export`` of the LQE course: one row per student, points per question.

``nbgrader export --exporter=lqe_helpers.grading.nbgrader_export.QuestionPointsExport
[--to grades.csv]`` (needs the ``grading`` extra). Columns: ``student``, then for each
notebook of each assignment ``(a) automatic`` (points of its check cells, as autograded)
and ``(a) by hand`` (its written answers once marked; empty until then); a notebook a
student did not submit is empty. The file is written atomically.
"""

from __future__ import annotations

import csv
import io

from nbgrader.api import Gradebook, MissingEntry
from nbgrader.plugins import ExportPlugin

from lqe_helpers.authoring.files import atomic_write_text
from lqe_helpers.grading.rules import question_label


class QuestionPointsExport(ExportPlugin):
    """Export the automatic and hand-marked points of each question, a row per student."""

    def export(self, gradebook: Gradebook) -> None:
        """Write the table to ``self.to`` (default ``grades.csv``)."""
        columns, rows = ["student"], []
        for student in gradebook.students:
            if self.student and student.id not in self.student:
                continue
            row = {"student": student.id}
            for assignment in gradebook.assignments:
                if self.assignment and assignment.name not in self.assignment:
                    continue
                for notebook in assignment.notebooks:
                    label = question_label(notebook.name)
                    auto, by_hand = f"{label} automatic", f"{label} by hand"
                    columns += [name for name in (auto, by_hand) if name not in columns]
                    try:
                        graded = gradebook.find_submission_notebook(
                            notebook.name, assignment.name, student.id)
                    except MissingEntry:
                        continue
                    code = [grade for grade in graded.grades if grade.cell_type == "code"]
                    text = [grade for grade in graded.grades if grade.cell_type == "markdown"]
                    row[auto] = f"{sum(grade.score for grade in code):g}"
                    if all(grade.manual_score is not None for grade in text):
                        row[by_hand] = f"{sum(grade.score for grade in text):g}"
            rows.append(row)
        table = io.StringIO()
        writer = csv.DictWriter(table, columns, restval="", lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
        atomic_write_text(self.to or "grades.csv", table.getvalue())
