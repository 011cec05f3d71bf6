"""Course tools for instructors and authors.

Run notebooks, build handouts, build the student edition, its pack and the marking guide.
Not imported by the science modules or the explorers; run as
``python -m lqe_helpers.authoring.<tool>``.
"""
