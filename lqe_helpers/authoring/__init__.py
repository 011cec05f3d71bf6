"""Course tools for instructors and authors: run notebooks, build handouts, build the student edition.

Not imported by the science modules or the explorers; run as ``python -m lqe_helpers.authoring.…``.
"""
