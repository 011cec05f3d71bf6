"""Remove what the course tools wrote in their output folders, and nothing else (``make clean``).

``python -m lqe_helpers.authoring.clean build/handouts build/student ...`` deletes, in each
folder, the files listed in its manifest (``.lqe-manifest.json``) that still hold exactly
what the tool wrote, then the manifest and the folders left empty. A file the tools did
not write, or one changed since, is kept and named. A folder without a manifest is left
as it is. Needs only the standard library, so it runs even when ``.venv`` is broken.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from lqe_helpers.authoring.command_line import CommandLineParser, run_command
from lqe_helpers.authoring.manifest import MANIFEST_NAME, read_manifest
from lqe_helpers.authoring.output_folder import remove_output_folder


def clean(folders: Sequence[Path | str]) -> list[str]:
    """Clean each output folder (:func:`~lqe_helpers.authoring.output_folder.remove_output_folder`).

    Returns
    -------
    list of str
        One line per folder that still exists afterwards, saying what was kept and why.
    """
    report = []
    for folder in map(Path, folders):
        if not folder.exists():
            continue
        if not folder.is_dir():
            report.append(f"kept {folder}: a file, not an output folder")
            continue
        if read_manifest(folder) is None:
            report.append(f"kept {folder}: it has no {MANIFEST_NAME}, so nothing in it is known "
                          f"to be the tools' (delete it yourself if it is)")
            continue
        _, kept = remove_output_folder(folder)
        if kept:
            names = ", ".join(path.relative_to(folder).as_posix() for path in kept[:5])
            more = f" and {len(kept) - 5} more" if len(kept) > 5 else ""
            report.append(f"kept in {folder}: {names}{more} (not written by the tools, or "
                          f"changed since)")
    return report


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: clean the folders named."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.clean",
                               description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path, metavar="FOLDER")

    def command(args: argparse.Namespace) -> int:
        for line in clean(args.folders):
            print(line)
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
