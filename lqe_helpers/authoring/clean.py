"""Remove what the course tools wrote in their output folders, and nothing else (``make clean``).

``python -m lqe_helpers.authoring.clean build/handouts build/student ...`` deletes, in each
folder, the files listed in its manifest (``.lqe-manifest.json``) that still hold exactly
what the tool wrote, then the manifest and the folders left empty. A file the tools did
not write, or one changed since, is kept and named. A build killed part-way is finished
or undone first, before the folder is read. A folder without a manifest, or whose manifest lists
a name outside it, is left as it is (the latter with an ``error:`` line and exit status
1). Needs only the standard library, so it runs even when ``.venv`` is broken.
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import sys
    from collections.abc import Sequence
    from pathlib import Path

    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import OutputFolderError, error_line, shown, summarise
    from lqe_helpers.authoring.manifest import MANIFEST_NAME
    from lqe_helpers.authoring.output_folder import remove_output_folder


def clean(folders: Sequence[Path | str]) -> tuple[list[str], list[str]]:
    """Clean each output folder (:func:`~lqe_helpers.authoring.output_folder.remove_output_folder`).

    A folder that cannot be cleaned safely (its manifest lists a name outside it, another
    tool is writing it) is left entirely as it is, and the others are still cleaned.

    Returns
    -------
    report : list of str
        One line per folder that still exists afterwards, saying what was kept and why.
    errors : list of str
        One line per folder left alone because cleaning it was refused.
    """
    report, errors = [], []
    for folder in map(Path, folders):
        if not folder.exists() and not folder.is_symlink():
            continue
        if not folder.is_dir():
            report.append(f"kept {shown(folder)}: a file, not an output folder")
            continue
        try:
            result = remove_output_folder(folder)  # held and recovered first, then read
        except (OutputFolderError, OSError) as error:
            errors.append(error_line(error))
            continue
        if result is None:
            report.append(f"kept {shown(folder)}: it has no {MANIFEST_NAME}, so nothing in it "
                          f"is known to be the tools' (delete it yourself if it is)")
            continue
        _, kept = result
        if kept:
            names = summarise([path.relative_to(folder).as_posix() for path in kept], 5)
            report.append(f"kept in {shown(folder)}: {names} (not written by the tools, or "
                          f"changed since)")
    return report, errors


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: clean the folders named."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.clean",
                               description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path, metavar="FOLDER")

    def command(args: argparse.Namespace) -> int:
        report, errors = clean(args.folders)
        for line in report:
            print(line)
        for line in errors:
            print(f"error: {line}", file=sys.stderr)
        return 1 if errors else 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
