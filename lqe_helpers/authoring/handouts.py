"""Build HTML handouts: every notebook executed fresh and rendered as one offline page.

``python -m lqe_helpers.authoring.handouts [--source notebooks] [--out build/handouts]`` (or
``make handouts``) writes::

    build/handouts/index.html          links to every page, in notebook order
    build/handouts/NN_name.html        one page per notebook: prose, code and figures
    build/handouts/prose/index.html    the same without code cells
    build/handouts/prose/NN_name.html  prose, printed results and figures only

Each notebook is executed once, in a fresh kernel, by
:func:`lqe_helpers.authoring.execution.execute_notebook`. A notebook that raises, shows an
error output, or displays a widget with no static view (which a page could only show
as a placeholder) stops the build, and the message names the notebook and the cell
(and gives the traceback); output on stderr (a warning) is reported but kept. A cell
may run ``--timeout`` seconds (default 300). Only once every page is ready is anything
written, all together or not at all (:mod:`lqe_helpers.authoring.output_folder`): the folder's
manifest ``.lqe-manifest.json`` lists what the build wrote, so the next build replaces or
deletes only those files (the page of a notebook since renamed goes) and only while they
are unchanged. Any other file there (an instructor's ``course_home.html``) is never
touched; one in the way of a page stops the build before anything is written.
Pages are rendered by nbconvert's ``HTMLExporter`` (lab template) with:

- every figure embedded as a base64 ``data:`` URI (outputs and markdown images);
- the widget-view mimetype left out of the display priority, so an explorer shows
  its static figure at the default values with a note that the sliders live in
  JupyterLab, never a widget placeholder;
- no require.js, widget-manager or mermaid scripts; MathJax is copied into the folder
  (``mathjax/``) and typesets every equation with no network, and every figure and
  page carries the accessibility of :mod:`lqe_helpers.authoring.handout_pages`;
- nbconvert's ``TagRemovePreprocessor`` honouring the usual ``remove-cell``,
  ``remove-input`` and ``remove-output`` tags, should an author want a cell hidden;
- markdown links to another notebook of the pack (``03_fusion.ipynb#...``) pointed
  at its page (``03_fusion.html#...``).
"""

from __future__ import annotations

from lqe_helpers.authoring.command_line import interrupt_exits_quietly

with interrupt_exits_quietly(__name__):  # Ctrl-C while importing: one line
    import argparse
    import copy
    import warnings
    from collections.abc import Sequence
    from dataclasses import dataclass
    from pathlib import Path
    from urllib.parse import quote

    import nbformat
    from nbconvert.filters import strip_ansi

    from lqe_helpers.authoring import handout_pages
    from lqe_helpers.authoring.command_line import CommandLineParser, run_command
    from lqe_helpers.authoring.errors import ToolError, shown, summarise
    from lqe_helpers.authoring.execution import (
        CELL_TIMEOUT,
        WIDGET_VIEW_MIMETYPE,
        NotebookRunError,
        execute_notebook,
        positive_seconds,
    )
    from lqe_helpers.authoring.handout_pages import handout_exporter
    from lqe_helpers.authoring.notebook_io import source_notebooks
    from lqe_helpers.authoring.output_folder import build_output_folder

#: Folder (inside the output folder) of the variant without code cells.
PROSE_DIR = "prose"
#: Title of the index pages.
PACK_TITLE = "The Linear Quadratic Estimator: tracking a butterfly"
#: ``mathjax_url`` that copies MathJax into the output folder and loads it from there
#: (the default).
LOCAL_MATHJAX = "local"

#: Name the handouts build records in its output folder's manifest.
TOOL_NAME = "handouts"


class HandoutBuildError(ToolError, RuntimeError):
    """A notebook could not be turned into a handout (it raised, or shows an error)."""


class HandoutWarning(UserWarning):
    """A handout page will show something a reader should not need (a warning)."""


@dataclass(frozen=True)
class Page:
    """One handout page: the notebook's file stem and its title."""

    stem: str
    title: str

    @property
    def file_name(self) -> str:
        """The page's file name (``<stem>.html``, spaces and accents as they are)."""
        return f"{self.stem}.html"

    @property
    def href(self) -> str:
        """The page's link relative to its index: the file name, URL-quoted (UTF-8)."""
        return quote(self.file_name)


def notebook_title(notebook: nbformat.NotebookNode, fallback: str) -> str:
    """The notebook's first level-1 markdown heading, else its first heading, else ``fallback``."""
    headings = [
        line for cell in notebook.cells if cell.cell_type == "markdown"
        for line in cell.source.splitlines() if line.startswith("#") and line.strip("# ")
    ]
    for line in headings:
        if line.startswith("# "):
            return line[2:].strip()
    return headings[0].lstrip("#").strip() if headings else fallback


def _index_notebook(pages: Sequence[Page], *, code: bool) -> nbformat.NotebookNode:
    """A one-cell notebook whose markdown lists ``pages`` in order (the index page)."""
    if code:
        intro = ("Each page is a notebook of the pack, executed afresh: the text, the code and "
                 "every figure. The interactive explorers appear as a figure at their default "
                 "values; open the notebooks in JupyterLab to move their sliders. Also here: "
                 f"[the same pages without code]({PROSE_DIR}/index.html).")
    else:
        intro = ("Each page is a notebook of the pack, executed afresh, showing its text, "
                 "printed results and figures without the code. The interactive explorers "
                 "appear as a figure at their default values; open the notebooks in JupyterLab "
                 "to move their sliders. Also here: [the same pages with code](../index.html).")
    items = []
    for number, page in enumerate(pages, start=1):
        title = page.title.replace("[", r"\[").replace("]", r"\]")
        items.append(f"{number}. [{title}]({page.href})")
    heading = f"# {PACK_TITLE}" + ("" if code else " (without code)")
    source = "\n".join([heading, "", intro, "", *items])
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell(source)])
    notebook.metadata["title"] = PACK_TITLE
    return notebook


def output_problems(notebook: nbformat.NotebookNode) -> dict[str, list[str]]:
    """What a page of ``notebook`` would show that a reader should not see, in one pass.

    ``"error"``: ``"cell N: Name: message"`` per error output; ``"traceback"``: its
    traceback as plain text headed ``"cell N:"``; ``"widget"``: a widget displayed with
    nothing but text beside it (an explorer's output also carries its figure; a bare
    ipywidget only ``text/plain``, which a page would show in place of the sliders);
    ``"stderr"``: ``"cell N: first line"`` per stream printed to stderr. ``N`` counts
    every cell (markdown included) from 0.
    """
    found: dict[str, list[str]] = {"error": [], "traceback": [], "widget": [], "stderr": []}
    static = set(handout_pages.DISPLAY_PRIORITY) - {"text/plain"}
    for index, cell in enumerate(notebook.cells):
        for output in cell.get("outputs", []):
            data, kind = output.get("data", {}), output.get("output_type")
            if kind == "error":
                found["error"].append(f"cell {index}: {output.get('ename')}: "
                                      f"{output.get('evalue')}")
                found["traceback"].append(f"cell {index}:\n" + strip_ansi(
                    "\n".join(output.get("traceback", []))).strip())
            elif kind == "stream" and output.get("name") == "stderr":
                first = (output.get("text", "").strip().splitlines() or [""])[0]
                found["stderr"].append(f"cell {index}: {first}")
            if WIDGET_VIEW_MIMETYPE in data and not static & set(data):
                found["widget"].append(f"cell {index}: {data.get('text/plain', 'a widget')!s:.60}")
    return found


def _execute(path: Path, timeout: float = CELL_TIMEOUT) -> nbformat.NotebookNode:
    """Execute ``path`` fresh; raise :class:`HandoutBuildError` if its page would be broken.

    Every cell runs even after one raises, so the message can name the cells that
    show an error (the first few, and how many more: the first is usually the cause;
    later ones may follow from it) and give the first traceback. A cell past
    ``timeout`` seconds or a kernel that dies stops the build too. Warns
    (:class:`HandoutWarning`) if a cell printed to stderr.
    """
    try:
        notebook = execute_notebook(path, timeout, allow_errors=True)
    except NotebookRunError as error:
        raise HandoutBuildError(str(error)) from error
    found = output_problems(notebook)
    if found["error"]:
        raise HandoutBuildError(f"{path} shows error output(s): "
                                f"{summarise(found['error'], separator='; ')}\n"
                                f"Traceback of the first, {found['traceback'][0]}")
    if found["widget"]:
        raise HandoutBuildError(
            f"{path} displays widget(s) with no static view, which a page could only show "
            f"as a placeholder (display an Explorer, or a figure): "
            f"{summarise(found['widget'], separator='; ')}")
    broken = handout_pages.broken_pngs(notebook)
    if broken:
        raise HandoutBuildError(f"{path} shows image/png output(s) that are not a valid PNG, "
                                f"which its page could not show: "
                                f"{summarise(broken, separator='; ')}")
    undescribed = handout_pages.undescribed_figures(notebook)
    if undescribed:
        warnings.warn(f"{path} shows figure(s) with no description, which its page can "
                      f"only give a generic alt text (show them with plotting.show_figure): "
                      f"{summarise(undescribed, separator='; ')}",
                      HandoutWarning, stacklevel=3)
    if found["stderr"]:
        warnings.warn(f"{path} prints to stderr, which its page will show: "
                      f"{summarise(found['stderr'], separator='; ')}", HandoutWarning,
                      stacklevel=3)
    return notebook


def _page_names(stems: Sequence[str]) -> list[str]:
    """The files a build writes for notebooks ``stems``, relative to the output folder."""
    return [f"{folder}{name}" for folder in ("", f"{PROSE_DIR}/")
            for name in [*(f"{stem}.html" for stem in stems), "index.html"]]


def build_handouts(source_dir: Path, out_dir: Path, *,
                   mathjax_url: str = LOCAL_MATHJAX,
                   timeout: float = CELL_TIMEOUT) -> list[Path]:
    """Execute every notebook in ``source_dir`` and write its handout pages to ``out_dir``.

    The output folder is checked before any notebook runs, and written only once every
    page is ready, all together (:func:`~lqe_helpers.authoring.output_folder.build_output_folder`):
    any failure leaves it as it was. The build records what it wrote in the folder's
    manifest (``.lqe-manifest.json``); a rebuild replaces or deletes only those files,
    and only while they are unchanged. Every other file in the folder (an instructor's
    ``course_home.html``) is left alone, and one in the way of a page stops the build.

    Parameters
    ----------
    source_dir : Path
        Folder of the source notebooks (``*.ipynb``, in name order; read only).
    out_dir : Path
        Output folder (created if needed); must not be, contain or lie inside
        ``source_dir``. Receives ``NN_name.html`` per notebook and ``index.html``;
        ``out_dir/prose/`` receives the same without code cells. Pages of an earlier
        build that this one does not write (a renamed notebook) are deleted.
    mathjax_url : str
        :data:`LOCAL_MATHJAX` (default): MathJax is copied into ``out_dir/mathjax/``
        (:func:`handout_pages.mathjax_copy`, listed in the manifest, not in the returned
        list) and every page loads it from there, so the folder works offline anywhere.
        Any other URL is loaded as it is (asynchronously); ``""`` leaves MathJax out.
    timeout : float
        Seconds one cell may run.

    Returns
    -------
    list of Path
        The pages with code in notebook order, then ``index.html``, then the
        prose pages and ``prose/index.html``.

    Raises
    ------
    ValueError
        If ``source_dir`` holds no notebook or a source notebook is not a valid one.
    OutputFolderError
        If ``out_dir`` is a file, overlaps ``source_dir``, or holds a file in the way
        of a page that this tool did not write (or that was changed since).
    OutputWriteError
        If writing fails (disk full, read-only folder); ``out_dir`` is as it was.
    HandoutBuildError
        If a notebook raises, shows an error output, displays a widget with no static
        view, runs a cell past ``timeout`` or kills its kernel.
    """
    source_dir, out_dir = Path(source_dir), Path(out_dir)
    paths = source_notebooks(source_dir)
    local = mathjax_url == LOCAL_MATHJAX
    mathjax = handout_pages.mathjax_copy() if local else {}
    page_names = _page_names([path.stem for path in paths])

    def pages() -> dict[str, str | bytes]:
        files = _render_pages([(path, _execute(path, timeout)) for path in paths],
                              mathjax_url=mathjax_url)
        files.update(mathjax)  # listed in the manifest too
        return files

    written = build_output_folder(out_dir, [*page_names, *mathjax], pages, tool=TOOL_NAME,
                                  sources=[source_dir])
    return written[:len(page_names)]


def _render_pages(executed: Sequence[tuple[Path, nbformat.NotebookNode]], *,
                  mathjax_url: str) -> dict[str, str | bytes]:
    """Every page of the build (with and without code, and the two index pages)."""
    local = mathjax_url == LOCAL_MATHJAX
    pages = [Page(path.stem, notebook_title(notebook, path.stem)) for path, notebook in executed]
    files: dict[str, str | bytes] = {}
    for code, folder in ((True, ""), (False, f"{PROSE_DIR}/")):
        page_mathjax = handout_pages.mathjax_url(folder.count("/")) if local else mathjax_url
        exporter = handout_exporter(code=code, mathjax_url=page_mathjax,
                                    stems=[page.stem for page in pages])
        for number, ((path, notebook), page) in enumerate(zip(executed, pages, strict=True)):
            nav = {
                "index": "index.html",
                "previous": pages[number - 1] if number > 0 else None,
                "next": pages[number + 1] if number + 1 < len(pages) else None,
            }
            notebook = copy.deepcopy(notebook)
            notebook.metadata["title"] = page.title
            resources = {"metadata": {"name": page.stem, "path": str(path.parent.resolve())},
                         "lqe_nav": nav}
            html, _ = exporter.from_notebook_node(notebook, resources)
            files[folder + page.file_name] = html
        html, _ = exporter.from_notebook_node(
            _index_notebook(pages, code=code), {"metadata": {"name": "index"}})
        files[folder + "index.html"] = html
    return files


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: build the handouts and list the files written."""
    parser = CommandLineParser(prog="python -m lqe_helpers.authoring.handouts",
                               description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the source notebooks (default: notebooks)")
    parser.add_argument("--out", type=Path, default=Path("build/handouts"),
                        help="output folder (default: build/handouts); a rebuild replaces only "
                             "the files listed in its .lqe-manifest.json")
    parser.add_argument("--mathjax-url", default=LOCAL_MATHJAX,
                        help=f"where pages load MathJax from: '{LOCAL_MATHJAX}' (default) copies "
                             "it into the output folder; '' for none (LaTeX shown as text)")
    parser.add_argument("--timeout", type=positive_seconds, default=CELL_TIMEOUT,
                        metavar="SECONDS",
                        help=f"seconds one cell may run before the build stops "
                             f"(default: {CELL_TIMEOUT})")

    def command(args: argparse.Namespace) -> int:
        for path in build_handouts(args.source, args.out, mathjax_url=args.mathjax_url,
                                   timeout=args.timeout):
            print(shown(path))
        return 0

    return run_command(parser, command, argv)


if __name__ == "__main__":
    raise SystemExit(main())
