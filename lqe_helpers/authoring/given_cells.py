"""Write ``lqe_helpers/student_code/_given_cell_keys.py``: the given cells and their places.

``python -m lqe_helpers.authoring.given_cells [--source notebooks]`` (run by
``make notebooks``) reads every notebook of the source folder and writes the key
(:func:`~lqe_helpers.student_code.given_cells.cell_key`) of each code cell not tagged
``solution`` (the cells every edition hands out as they are) with its places (notebook,
index among its code cells), and the places of each task's ``# Task:`` line. Run it after changing a
notebook's cells; ``tests/student_code/test_given_cells.py`` says when it is due.
The module is written atomically; nothing else is touched.
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    from collections.abc import Sequence
    from pathlib import Path

    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.files import atomic_write_text
    from lqe_helpers.authoring.notebook_io import read_notebook
    from lqe_helpers.authoring.task_cells import SOLUTION_TAG, cell_tags
    from lqe_helpers.student_code import given_cells
    from lqe_helpers.student_code.given_cells import Places

#: The generated module.
KEYS_MODULE = Path(given_cells.__file__).with_name("_given_cell_keys.py")


def given_places(source_dir: Path) -> tuple[dict[str, Places], dict[str, Places]]:
    """The places of every code cell not tagged ``solution`` in ``source_dir``'s notebooks
    (by key) and of every task's ``# Task:`` line (by the line), each sorted."""
    given: dict[str, list[tuple[str, int]]] = {}
    tasks: dict[str, list[tuple[str, int]]] = {}
    for path in sorted(source_dir.glob("*.ipynb")):
        code = [cell for cell in read_notebook(path).cells if cell.cell_type == "code"]
        for index, cell in enumerate(code):
            if SOLUTION_TAG not in cell_tags(cell):
                given.setdefault(given_cells.cell_key(cell.source), []).append(
                    (path.stem, index))
            elif line := given_cells.task_line(cell.source):
                tasks.setdefault(line, []).append((path.stem, index))
    return ({key: tuple(found) for key, found in sorted(given.items())},
            {line: tuple(found) for line, found in sorted(tasks.items())})


def module_text(given: dict[str, Places], tasks: dict[str, Places]) -> str:
    """The text of ``_given_cell_keys.py`` holding ``given`` and ``tasks``."""
    def entries(table: dict[str, Places]) -> str:
        return "".join(f"    {key!r}: {found!r},\n" for key, found in table.items())

    return ('"""Places of the given code cells (by key) and of the ``# Task:`` lines: do not '
            'edit,\nrun python -m lqe_helpers.authoring.given_cells."""\n\n'
            f"GIVEN: dict[str, tuple[tuple[str, int], ...]] = {{\n{entries(given)}}}\n"
            f"TASKS: dict[str, tuple[tuple[str, int], ...]] = {{\n{entries(tasks)}}}\n")


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: write the keys of the source notebooks' given cells."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.given_cells",
                               description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the worked notebooks (default: notebooks)")

    def command(args: argparse.Namespace) -> int:
        given, tasks = given_places(args.source)
        if not given:
            raise ValueError(f"--source {args.source}: no notebook with a given code cell")
        atomic_write_text(KEYS_MODULE, module_text(given, tasks))
        print(f"{KEYS_MODULE}: {len(given)} given cells, {len(tasks)} task lines")
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
