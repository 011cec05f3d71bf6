"""Grading a class: nbgrader's course folder and export, and the grade tool without it.

Run as ``python -m lqe_helpers.grading.<tool>``. Built on :mod:`lqe_helpers.authoring`
(which never imports it back); never shipped to students.
"""
