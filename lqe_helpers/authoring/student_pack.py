"""The student pack: one zip a student unpacks and uses with ``make lab``.

``python -m lqe_helpers.authoring.student_pack [--root .] [--out build/student-pack]``
(or ``make student-pack``) writes ``lqe-student-pack.zip``. Unpacked, its folder
``lqe-student-pack/`` holds:

- ``notebooks/``: the student edition of every notebook (tasks as stubs, answers as
  prompts; built as ``make student`` builds it, and refused for the same reasons);
- ``lqe_helpers/``: the package, **without** ``lqe_helpers/authoring/`` and
  ``lqe_helpers/grading/``. Those are the instructor's tools (run notebooks, build
  handouts, the student edition, this pack, the marking guide, grading); nothing a
  student runs (notebooks, explorers, checks, ``make lab``, ``make test``) imports
  them, and leaving them out keeps the pack to what students use;
- ``README.md``: the students' own (:data:`STUDENT_README`: what to run, how to work a
  notebook, where help is), not the course's, which speaks to instructors and
  maintainers; ``pyproject.toml``, ``constraints.txt``;
- ``Makefile``: the pack's own, generated from the course's Makefile by keeping its
  variables and its ``$(BIN)/python``, ``$(STAMP)``, ``lab`` and ``clean`` rules word for
  word (so ``make lab`` is identical) and replacing ``test``: it runs ``pytest tests``
  (the unit tests and the structure checks below), without ruff and without nbval, which
  would stop at the first unfinished task by design;
- ``tests/``: only the tests listed in :data:`PACK_TESTS` (the pack's infrastructure:
  input checks, the student-code machinery, plotting; none holds a worked answer or a
  task's result), plus ``test_student_notebooks.py`` (the structure of the student
  notebooks: valid, student tags only, a check after every core task, imports that
  resolve) with its conventions in ``student_pack.json``. Every other test stays with the
  instructor: a list of what may ship, not of what may not, so a new test (a check's
  wrong answers, an oracle loop, a task's numbers) never reaches students by default;
- ``STUDENT-PACK.md``: what the pack is, how to start, and what was left out.

The marking guide is never in the pack. The zip is the same, byte for byte, for the same
sources (fixed file times and order), and is written atomically into a folder the tool
owns (:func:`lqe_helpers.authoring.output_folder.write_output_folder`).
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import io
    import json
    import re
    import zipfile
    from collections.abc import Sequence
    from pathlib import Path

    from lqe_helpers.authoring import student_edition as se
    from lqe_helpers.authoring import task_cells as tc
    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import shown
    from lqe_helpers.authoring.files import refuse_symlink
    from lqe_helpers.authoring.notebook_io import read_notebook, source_notebooks
    from lqe_helpers.authoring.output_folder import build_output_folder

#: Name of the tool in the output folder's manifest.
TOOL_NAME = "student_pack"
#: The folder a student gets when unpacking the zip.
PACK_NAME = "lqe-student-pack"
#: The zip written in the output folder.
ZIP_NAME = f"{PACK_NAME}.zip"
#: What the pack is, at its top level (also marks an unpacked folder as a student pack);
#: its text is the file of that name in :data:`PACK_FILES`.
MARKER_NAME = "STUDENT-PACK.md"
#: Files copied from the top of the course folder as they are.
TOP_FILES = ("pyproject.toml", "constraints.txt")
#: Folders of the course folder the pack copies from; its output folder may not overlap them.
SOURCES = ("notebooks", "lqe_helpers", "tests")
#: Sub-packages of lqe_helpers that stay with the instructor.
INSTRUCTOR_PACKAGES = ("authoring", "grading")
#: The only files of tests/ the pack ships (every other one stays with the instructor):
#: tests of the pack's infrastructure that hold no worked answer and no task's result.
PACK_TESTS = ("conftest.py", "test_validation.py", "test_public_errors.py",
              "test_memory_limits.py", "test_distributions.py",
              "student_code/test_student_code.py", "test_plotting.py", "explorers/test_png.py",
              "explorers/test_explorer_cache.py")
#: Rules of the course Makefile the pack keeps word for word.
KEPT_RULES = ("$(BIN)/python", "$(STAMP)", "lab", "clean")
#: A rule's first line in a Makefile (not a variable assignment with ``:=``).
RULE = re.compile(r"^([^\s#:=][^:=]*?)\s*::?(?!=)", re.MULTILINE)
#: The pack's own ``test`` rule.
PACK_TEST_RULE = """\
# Student pack: the unit tests of lqe_helpers and the structure of the student notebooks
# (valid, tags, a check after every core task, imports that resolve). The notebooks are
# not run: their tasks are yours to write, and the checks in them tell you when each is right.
test: $(STAMP)
\t$(BIN)/python -m pytest tests $(PYTEST_ARGS)"""
#: Where the files shipped only in the pack live in the course folder.
PACK_FILES = Path(__file__).resolve().parent / "student_pack_files"
#: The students' README, in :data:`PACK_FILES`; shipped as the pack's ``README.md``.
STUDENT_README = "README.md"
#: The structure test shipped in the pack's tests/.
STRUCTURE_TEST = "test_student_notebooks.py"
#: Its conventions, written at build time from the student edition's definitions.
CONVENTIONS_NAME = "student_pack.json"
#: Notebooks whose core tasks must each have a check (the tutorial's questions).
CHECKED_PREFIXES = ("01_", "02_", "03_", "04_", "05_")
#: Date and time of every file in the zip (the earliest a zip can hold): same sources,
#: same bytes.
ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def pack_makefile(course_makefile: str) -> str:
    """The pack's Makefile, made from the course's.

    Parameters
    ----------
    course_makefile : str
        The course Makefile's text.

    Returns
    -------
    str
        Its paragraphs of comments and variables and its rules :data:`KEPT_RULES`,
        word for word, in order; a ``.PHONY`` line for the pack's targets; and the
        pack's ``test`` rule (:data:`PACK_TEST_RULE`). Other rules are left out.

    Raises
    ------
    ValueError
        If a kept rule is missing, or shares a paragraph with a rule that is not kept.
    """
    kept, found = [], set()
    for paragraph in re.split(r"\n[ \t]*\n", course_makefile.strip("\n")):
        targets = {target for match in RULE.finditer(paragraph)
                   for target in match.group(1).split()}
        if targets == {".PHONY"}:
            kept.append(".PHONY: lab test clean")
        elif not targets:
            kept.append(paragraph)
        elif targets <= set(KEPT_RULES):
            kept.append(paragraph)
            found |= targets
            if "lab" in targets:  # the pack's test rule comes right after lab, as in the course
                kept.append(PACK_TEST_RULE)
        elif targets & set(KEPT_RULES):
            raise ValueError(f"the Makefile's rules {sorted(targets)} share one paragraph; "
                             f"put a blank line between kept rules {list(KEPT_RULES)} and others")
    missing = [rule for rule in KEPT_RULES if rule not in found]
    if missing:
        raise ValueError(f"the Makefile has no rule {', '.join(missing)}, which the student "
                         f"pack needs")
    return "\n\n".join(kept) + "\n"


def source_folders(root: Path) -> list[Path]:
    """The folders of the course folder ``root`` that the pack copies from (:data:`SOURCES`)."""
    return [Path(root) / name for name in SOURCES]


def _files_under(folder: Path) -> list[Path]:
    """Every regular file under ``folder``, sorted; ``__pycache__``, ``.pyc`` and ``.pyo`` left out.

    Raises
    ------
    ValueError
        Naming the first symbolic link, or the first entry that is neither a file nor a
        folder (a fifo, a device, a socket), found in ``folder``.
    """
    refuse_symlink(folder)
    found = []
    for path in sorted(folder.rglob("*")):
        if "__pycache__" in path.relative_to(folder).parts:
            continue
        refuse_symlink(path)
        if path.is_dir():
            continue
        if not path.is_file():
            raise ValueError(f"{shown(path)} is neither a file nor a folder (a fifo, device "
                             f"or socket); the student pack copies only files: remove it")
        if path.suffix not in {".pyc", ".pyo"}:
            found.append(path)
    return found


def _read_text(path: Path) -> str:
    """The UTF-8 text of the file ``path`` (not a link); a failure names the file."""
    refuse_symlink(path)
    data = path.read_bytes()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ValueError(f"{shown(path)} is not UTF-8 text ({error.reason} at byte "
                         f"{error.start}); save it as UTF-8") from None


def pack_contents(root: Path, *, allow_without_solutions: bool = False) -> dict[str, bytes]:
    """Every file of the student pack: path inside the pack → content.

    Parameters
    ----------
    root : Path
        The course folder (with ``notebooks/``, ``lqe_helpers/``, ``tests/``, the
        Makefile and :data:`TOP_FILES`). Only read.
    allow_without_solutions : bool
        Build the edition of a notebook that has no ``solution`` cell (with a warning),
        as ``make student --allow-without-solutions`` does.

    Returns
    -------
    dict of str to bytes
        Relative POSIX paths (without the top folder) in a fixed order.

    Raises
    ------
    ValueError
        If a needed file is missing, a notebook breaks the tag convention or has no
        solution cell, the Makefile lacks a rule the pack keeps, a file to copy is a
        symbolic link or not a regular file, or a text file or a file's name is not
        UTF-8 (the message names the file).
    """
    root = Path(root)
    for needed in ("Makefile", *TOP_FILES, "lqe_helpers/__init__.py", "tests",
                   *(f"tests/{name}" for name in PACK_TESTS)):
        if not (root / needed).exists():
            raise ValueError(f"root must be the course folder; {root / needed} is missing")
    files: dict[str, bytes] = {}
    names = []
    for path in source_notebooks(root / "notebooks"):
        notebook = read_notebook(path)
        se.check_has_solutions(notebook, path.name,
                               allow_without_solutions=allow_without_solutions)
        files[f"notebooks/{path.name}"] = se.student_edition(notebook, path.stem).encode()
        names.append(path.name)
    for path in _files_under(root / "lqe_helpers"):
        relative = path.relative_to(root / "lqe_helpers")
        if relative.parts[0] not in INSTRUCTOR_PACKAGES:
            files[f"lqe_helpers/{relative.as_posix()}"] = path.read_bytes()
    for name in PACK_TESTS:
        path = root / "tests" / name
        refuse_symlink(path)
        if not path.is_file():
            raise ValueError(f"{shown(path)} is not a regular file (a fifo, a device or a "
                             f"folder); the student pack copies only files: put the test "
                             f"itself there")
        files[f"tests/{name}"] = _read_text(path).encode()  # non-UTF-8 text stops it, named
    files[f"tests/{STRUCTURE_TEST}"] = (PACK_FILES / STRUCTURE_TEST).read_bytes()
    conventions = {
        "tags": sorted(se.STUDENT_TAGS), "task_tag": tc.TASK_TAG,
        "task_prefix": tc.TASK_PREFIX, "check_call": tc.CHECK_CALL,
        "going_further": tc.GOING_FURTHER, "notebooks": names,
        "checked_notebooks": [name for name in names if name.startswith(CHECKED_PREFIXES)],
    }
    files[f"tests/{CONVENTIONS_NAME}"] = (json.dumps(conventions, indent=1) + "\n").encode()
    files["Makefile"] = pack_makefile(_read_text(root / "Makefile")).encode()
    files["README.md"] = _read_text(PACK_FILES / STUDENT_README).encode()
    for name in TOP_FILES:
        files[name] = _read_text(root / name).encode()
    files[MARKER_NAME] = _read_text(PACK_FILES / MARKER_NAME).encode()
    for name in files:  # a zip names its files in UTF-8
        if name.encode("utf-8", "replace").decode("utf-8") != name:
            raise ValueError(f"{shown(root / name)}: its name is not UTF-8; the student pack "
                             f"(a zip) names its files in UTF-8: rename it")
    return dict(sorted(files.items()))


def zip_bytes(files: dict[str, bytes]) -> bytes:
    """A zip of ``files`` under the top folder :data:`PACK_NAME`, the same bytes every time."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name, data in files.items():
            info = zipfile.ZipInfo(f"{PACK_NAME}/{name}", date_time=ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, data)
    return buffer.getvalue()


def build_student_pack(root: Path, out_dir: Path, *,
                       allow_without_solutions: bool = False) -> Path:
    """Write :data:`ZIP_NAME` for the course folder ``root`` into ``out_dir``.

    Parameters
    ----------
    root : Path
        The course folder (only read).
    out_dir : Path
        Folder for the zip (created if needed). The tool replaces only what it wrote
        there, atomically; it must not be, contain or lie inside a folder the pack
        copies from (:data:`SOURCES`).
    allow_without_solutions : bool
        See :func:`pack_contents`.

    Returns
    -------
    Path
        The zip.

    Raises
    ------
    ValueError
        See :func:`pack_contents`; and :class:`~lqe_helpers.authoring.errors.OutputFolderError`
        if ``out_dir`` cannot be used.
    """
    root = Path(root)

    def pack() -> dict[str, bytes]:
        contents = pack_contents(root, allow_without_solutions=allow_without_solutions)
        return {ZIP_NAME: zip_bytes(contents)}

    [written] = build_output_folder(out_dir, [ZIP_NAME], pack, tool=TOOL_NAME,
                                    sources=source_folders(root))
    return written


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: build the student pack and print the zip's path."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.student_pack",
                               description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path("."),
                        help="the course folder (default: the current folder)")
    parser.add_argument("--out", type=Path, default=Path("build/student-pack"),
                        help="folder for lqe-student-pack.zip (default: build/student-pack)")
    parser.add_argument("--allow-without-solutions", action="store_true",
                        help="pack notebooks that have no 'solution' cell (with a warning) "
                             "instead of refusing")

    def command(args: argparse.Namespace) -> int:
        print(shown(build_student_pack(args.root, args.out,
                                 allow_without_solutions=args.allow_without_solutions)))
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
