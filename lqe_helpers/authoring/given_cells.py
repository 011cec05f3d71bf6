"""Write ``lqe_helpers/student_code/_given_cell_keys.py``: the keys of the given cells.

``python -m lqe_helpers.authoring.given_cells [--source notebooks]`` (run by
``make notebooks``) reads every notebook of the source folder and writes the key
(:func:`~lqe_helpers.student_code.given_cells.cell_key`) of each code cell not tagged
``solution``: the cells every edition hands out as they are. Run it after changing a
notebook's given cells; ``tests/student_code/test_given_cells.py`` says when it is due.
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

#: The generated module.
KEYS_MODULE = Path(given_cells.__file__).with_name("_given_cell_keys.py")


def given_keys(source_dir: Path) -> list[str]:
    """The sorted keys of every code cell not tagged ``solution`` in ``source_dir``'s notebooks."""
    keys = set()
    for path in sorted(source_dir.glob("*.ipynb")):
        for cell in read_notebook(path).cells:
            if cell.cell_type == "code" and SOLUTION_TAG not in cell_tags(cell):
                keys.add(given_cells.cell_key(cell.source))
    return sorted(keys)


def module_text(keys: Sequence[str]) -> str:
    """The text of ``_given_cell_keys.py`` holding ``keys``."""
    lines = "".join(f'    "{key}",\n' for key in keys)
    return ('"""Keys of the given code cells: do not edit, run\n'
            'python -m lqe_helpers.authoring.given_cells."""\n\n'
            f"GIVEN: frozenset[str] = frozenset({{\n{lines}}})\n")


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: write the keys of the source notebooks' given cells."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.given_cells",
                               description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the worked notebooks (default: notebooks)")

    def command(args: argparse.Namespace) -> int:
        keys = given_keys(args.source)
        if not keys:
            raise ValueError(f"--source {args.source}: no notebook with a given code cell")
        atomic_write_text(KEYS_MODULE, module_text(keys))
        print(f"{KEYS_MODULE}: {len(keys)} given cells")
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
