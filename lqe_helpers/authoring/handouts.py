"""Build HTML handouts: every notebook executed fresh and rendered as one offline page.

``python -m lqe_helpers.authoring.handouts [--source notebooks] [--out build/handouts]`` (or
``make handouts``) writes::

    build/handouts/index.html          links to every page, in notebook order
    build/handouts/NN_name.html        one page per notebook: prose, code and figures
    build/handouts/prose/index.html    the same without code cells
    build/handouts/prose/NN_name.html  prose, printed results and figures only

Each notebook is executed once, in a fresh kernel, by
:func:`lqe_helpers.authoring.notebook_runner.execute_notebook`. A notebook that raises, shows an
error output, or displays a widget with no static view (which a page could only show
as a placeholder) stops the build, and the message names the notebook and the cell
(and gives the traceback); output on stderr (a warning) is reported but kept. Only
once every notebook has run is anything written: then every other ``*.html`` file
directly in the output folder or its ``prose/`` folder (the page of a notebook since
renamed or removed) is deleted, so the folders hold exactly the current pages.
Pages are rendered by nbconvert's ``HTMLExporter`` (lab template) with:

- every figure embedded as a base64 ``data:`` URI (outputs and markdown images);
- the widget-view mimetype left out of the display priority, so an explorer shows
  its static figure at the default values with a note that the sliders live in
  JupyterLab, never a widget placeholder;
- no require.js, widget-manager or mermaid scripts. MathJax is the one remote script
  and loads ``async``: offline, the equations stay readable as their LaTeX source
  and nothing waits for the network;
- nbconvert's ``TagRemovePreprocessor`` honouring the usual ``remove-cell``,
  ``remove-input`` and ``remove-output`` tags, should an author want a cell hidden;
- markdown links to another notebook of the pack (``03_fusion.ipynb#...``) pointed
  at its page (``03_fusion.html#...``).
"""

from __future__ import annotations

import argparse
import copy
import re
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import nbformat
from jinja2 import DictLoader
from nbclient.exceptions import CellTimeoutError, DeadKernelError
from nbconvert.exporters import HTMLExporter
from nbconvert.filters import strip_ansi
from nbconvert.preprocessors import Preprocessor
from traitlets import List, Unicode
from traitlets.config import Config

from lqe_helpers.authoring.notebook_runner import WIDGET_VIEW_MIMETYPE, execute_notebook, fail
from lqe_helpers.authoring.student_edition import check_out_dir, remove_stale, source_notebooks

#: Folder (inside the output folder) of the variant without code cells.
PROSE_DIR = "prose"
#: Title of the index pages.
PACK_TITLE = "The Linear Quadratic Estimator: tracking a butterfly"
#: Where MathJax comes from; an empty string leaves it out (equations stay as LaTeX).
DEFAULT_MATHJAX_URL = (
    "https://cdnjs.cloudflare.com/ajax/libs/mathjax/2.7.7/MathJax.js?config=TeX-AMS_CHTML-full,Safe"
)
#: What an HTML page may show from a display bundle, best first. The widget view is
#: not in the list: with no widget manager it could only render as a placeholder.
DISPLAY_PRIORITY = [
    "text/html",
    "text/markdown",
    "image/svg+xml",
    "text/latex",
    "image/png",
    "image/jpeg",
    "text/plain",
]

_TEMPLATE_NAME = "lqe_handout.html.j2"
_TEMPLATE = r"""
{%- extends 'index.html.j2' -%}

{%- macro lqe_nav(nav) -%}
{%- if nav -%}
<nav class="lqe-nav" aria-label="Handout pages">
  <span>{%- if nav.previous -%}
    <a rel="prev" href="{{ nav.previous.href }}">&larr; {{ nav.previous.title | e }}</a>
  {%- endif -%}</span>
  <a href="{{ nav.index }}">All handouts</a>
  <span>{%- if nav.next -%}
    <a rel="next" href="{{ nav.next.href }}">{{ nav.next.title | e }} &rarr;</a>
  {%- endif -%}</span>
</nav>
{%- endif -%}
{%- endmacro -%}

{%- block html_head_js_requirejs -%}{%- endblock html_head_js_requirejs -%}
{%- block jupyter_widgets -%}{%- endblock jupyter_widgets -%}
{%- block html_head_js_mermaidjs -%}{%- endblock html_head_js_mermaidjs -%}

{%- block html_head_js_mathjax -%}
{%- if resources.mathjax_url -%}
<script type="text/x-mathjax-config">
MathJax.Hub.Config({
  TeX: {equationNumbers: {autoNumber: "AMS", useLabelIds: true}},
  tex2jax: {
    inlineMath: [["$", "$"], ["\\(", "\\)"]],
    displayMath: [["$$", "$$"], ["\\[", "\\]"]],
    processEscapes: true,
    processEnvironments: true
  },
  displayAlign: "center",
  messageStyle: "none",
  CommonHTML: {linebreaks: {automatic: true}}
});
</script>
<script async src="{{ resources.mathjax_url }}"></script>
{%- endif -%}
{%- endblock html_head_js_mathjax -%}

{%- block extra_css -%}
<style type="text/css">
nav.lqe-nav {
  display: flex; justify-content: space-between; gap: 1em;
  max-width: 1100px; margin: 0.5em auto; padding: 0.4em 1em;
  font-family: var(--jp-ui-font-family); font-size: 0.95em;
  border-bottom: 1px solid var(--jp-border-color2);
}
nav.lqe-nav + main, main + nav.lqe-nav { border-top: 1px solid var(--jp-border-color2); }
figure.lqe-explorer { margin: 0; }
figure.lqe-explorer img { max-width: 100%; height: auto; }
figure.lqe-explorer figcaption { color: var(--jp-content-font-color2); margin-top: 0.3em; }
</style>
{%- endblock extra_css -%}

{%- block body_header -%}
{{ super() }}
{{ lqe_nav(resources.lqe_nav) }}
{%- endblock body_header -%}

{%- block body_footer -%}
{{ lqe_nav(resources.lqe_nav) }}
{{ super() }}
{%- endblock body_footer -%}
"""


class HandoutBuildError(RuntimeError):
    """A notebook could not be turned into a handout (it raised, or shows an error)."""


class HandoutWarning(UserWarning):
    """A handout page will show something a reader should not need (a warning)."""


class NotebookLinkPreprocessor(Preprocessor):
    """Point markdown links to another notebook of the pack at that notebook's page.

    ``[see question (c)](03_fusion.ipynb#The-question)`` becomes a link to
    ``03_fusion.html#The-question``, in markdown and in raw ``href`` attributes. Only
    the notebooks named in ``stems`` are rewritten; any other link is left alone.
    """

    stems = List(Unicode(), help="File stems of the notebooks that have a page.").tag(
        config=True)

    _LINK = re.compile(
        r"""(?P<before>\]\(\s*<?|href\s*=\s*["'])(?:\./)?(?P<stem>[\w.-]+)\.ipynb"""
        r"""(?=[#)>"'\s])"""
    )

    def preprocess_cell(self, cell: nbformat.NotebookNode, resources: dict,
                        index: int) -> tuple[nbformat.NotebookNode, dict]:
        """Rewrite the links of a markdown cell."""
        if cell.cell_type == "markdown" and ".ipynb" in cell.source:
            stems = set(self.stems)
            cell.source = self._LINK.sub(
                lambda match: (f"{match['before']}{match['stem']}.html"
                               if match["stem"] in stems else match[0]),
                cell.source,
            )
        return cell, resources


@dataclass(frozen=True)
class Page:
    """One handout page: the notebook's file stem and its title."""

    stem: str
    title: str

    @property
    def href(self) -> str:
        """The page's file name, relative to its index."""
        return f"{self.stem}.html"


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


def error_outputs(notebook: nbformat.NotebookNode) -> list[str]:
    """Where ``notebook`` shows an error: ``"cell N: Name: message"`` per error output.

    ``N`` counts every cell (markdown included) from 0.
    """
    found = []
    for index, cell in enumerate(notebook.cells):
        for output in cell.get("outputs", []):
            if output.get("output_type") == "error":
                found.append(f"cell {index}: {output.get('ename')}: {output.get('evalue')}")
    return found


def error_tracebacks(notebook: nbformat.NotebookNode) -> list[str]:
    """The traceback of each error output, as plain text headed ``"cell N:"``.

    In the order of :func:`error_outputs`, without the terminal colour codes.
    """
    return [
        f"cell {index}:\n" + strip_ansi("\n".join(output.get("traceback", []))).strip()
        for index, cell in enumerate(notebook.cells)
        for output in cell.get("outputs", [])
        if output.get("output_type") == "error"
    ]


def unshowable_widgets(notebook: nbformat.NotebookNode) -> list[str]:
    """Where ``notebook`` displays a widget with nothing but text beside it.

    An explorer's output also carries its figure (``text/html`` and ``image/png``); a
    bare ipywidget carries only ``text/plain`` ("VBox(children=...)"), which is what
    a page would show in place of the sliders.
    """
    static = set(DISPLAY_PRIORITY) - {"text/plain"}
    return [
        f"cell {index}: {output.get('data', {}).get('text/plain', 'a widget')!s:.60}"
        for index, cell in enumerate(notebook.cells)
        for output in cell.get("outputs", [])
        if WIDGET_VIEW_MIMETYPE in output.get("data", {}) and not static & set(output["data"])
    ]


def stderr_outputs(notebook: nbformat.NotebookNode) -> list[str]:
    """Where ``notebook`` printed to stderr: ``"cell N: first line"`` per stream."""
    return [
        f"cell {index}: {(output.get('text', '').strip().splitlines() or [''])[0]}"
        for index, cell in enumerate(notebook.cells)
        for output in cell.get("outputs", [])
        if output.get("output_type") == "stream" and output.get("name") == "stderr"
    ]


def handout_exporter(*, code: bool = True, mathjax_url: str = DEFAULT_MATHJAX_URL,
                     stems: Sequence[str] = ()) -> HTMLExporter:
    """The HTML exporter for handout pages.

    Parameters
    ----------
    code : bool
        Show the code cells' source (``False`` for the prose variant: markdown,
        printed results and figures only, without prompts).
    mathjax_url : str
        Where MathJax is loaded from (``async``); ``""`` leaves MathJax out.
    stems : sequence of str
        File stems of the notebooks that get a page next to this one; markdown links
        to ``<stem>.ipynb`` are pointed at ``<stem>.html``.
    """
    config = Config()
    config.NbConvertBase.display_data_priority = list(DISPLAY_PRIORITY)
    config.HTMLExporter.embed_images = True
    config.HTMLExporter.mathjax_url = mathjax_url
    config.TagRemovePreprocessor.enabled = True
    config.TagRemovePreprocessor.remove_cell_tags = {"remove-cell"}
    config.TagRemovePreprocessor.remove_input_tags = {"remove-input"}
    config.TagRemovePreprocessor.remove_all_outputs_tags = {"remove-output"}
    if not code:
        config.TemplateExporter.exclude_input = True
        config.TemplateExporter.exclude_input_prompt = True
        config.TemplateExporter.exclude_output_prompt = True
    exporter = HTMLExporter(config=config, template_name="lab",
                            extra_loaders=[DictLoader({_TEMPLATE_NAME: _TEMPLATE})])
    exporter.template_file = _TEMPLATE_NAME
    exporter.register_preprocessor(NotebookLinkPreprocessor(stems=list(stems)), enabled=True)
    return exporter


def _index_notebook(pages: Sequence[Page], *, code: bool) -> nbformat.NotebookNode:
    """A one-cell notebook whose markdown lists ``pages`` in order (the index page)."""
    if code:
        intro = ("Each page is a notebook of the pack, executed afresh: the text, the code and "
                 "every figure. The interactive explorers appear as a figure at their default "
                 "values; open the notebooks in JupyterLab to move their sliders. The same pages "
                 f"without code are in [{PROSE_DIR}/]({PROSE_DIR}/index.html).")
    else:
        intro = ("Each page is a notebook of the pack, executed afresh, showing its text, "
                 "printed results and figures without the code. The interactive explorers "
                 "appear as a figure at their default values; open the notebooks in JupyterLab "
                 "to move their sliders. The pages with code are [here](../index.html).")
    items = []
    for number, page in enumerate(pages, start=1):
        title = page.title.replace("[", r"\[").replace("]", r"\]")
        items.append(f"{number}. [{title}]({page.href})")
    heading = f"# {PACK_TITLE}" + ("" if code else " (without code)")
    source = "\n".join([heading, "", intro, "", *items])
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell(source)])
    notebook.metadata["title"] = PACK_TITLE
    return notebook


def _execute(path: Path) -> nbformat.NotebookNode:
    """Execute ``path`` fresh; raise :class:`HandoutBuildError` if its page would be broken.

    Every cell runs even after one raises, so the message can name each cell that
    shows an error (the first is usually the cause; later ones may follow from it)
    and give the first traceback. Warns (:class:`HandoutWarning`) if a cell printed
    to stderr.
    """
    try:
        notebook = execute_notebook(path, allow_errors=True)
    except (CellTimeoutError, DeadKernelError) as error:
        raise HandoutBuildError(f"{path}: {error}") from error
    errors = error_outputs(notebook)
    if errors:
        raise HandoutBuildError(f"{path} shows error output(s): {'; '.join(errors)}\n"
                                f"Traceback of the first, {error_tracebacks(notebook)[0]}")
    widgets = unshowable_widgets(notebook)
    if widgets:
        raise HandoutBuildError(
            f"{path} displays widget(s) with no static view, which a page could only show "
            f"as a placeholder (display an Explorer, or a figure): {'; '.join(widgets)}")
    printed = stderr_outputs(notebook)
    if printed:
        warnings.warn(f"{path} prints to stderr, which its page will show: "
                      f"{'; '.join(printed)}", HandoutWarning, stacklevel=3)
    notebook.metadata.pop("widgets", None)
    return notebook


def build_handouts(source_dir: Path, out_dir: Path, *,
                   mathjax_url: str = DEFAULT_MATHJAX_URL) -> list[Path]:
    """Execute every notebook in ``source_dir`` and write its handout pages to ``out_dir``.

    Parameters
    ----------
    source_dir : Path
        Folder of the source notebooks (``*.ipynb``, in name order; read only).
    out_dir : Path
        Output folder (created if needed). Receives ``NN_name.html`` per notebook and
        ``index.html``; ``out_dir/prose/`` receives the same without code cells. Once
        every notebook has run, any other ``*.html`` file directly in either folder
        (left by an earlier build) is deleted; nothing else there is touched. A
        notebook that stops the build stops it before anything is written or deleted.
    mathjax_url : str
        Where the pages load MathJax from (asynchronously); ``""`` leaves it out.

    Returns
    -------
    list of Path
        The pages with code in notebook order, then ``index.html``, then the
        prose pages and ``prose/index.html``.

    Raises
    ------
    ValueError
        If ``source_dir`` holds no notebook or ``out_dir`` is ``source_dir``.
    HandoutBuildError
        If a notebook raises, shows an error output or displays a widget with
        no static view.
    """
    source_dir, out_dir = Path(source_dir), Path(out_dir)
    paths = source_notebooks(source_dir)
    check_out_dir(source_dir, out_dir)
    executed = [(path, _execute(path)) for path in paths]
    pages = [Page(path.stem, notebook_title(notebook, path.stem)) for path, notebook in executed]

    written = []
    names = {page.href for page in pages} | {"index.html"}
    for code, folder in ((True, out_dir), (False, out_dir / PROSE_DIR)):
        folder.mkdir(parents=True, exist_ok=True)
        remove_stale(folder, "*.html", keep=names)
        exporter = handout_exporter(code=code, mathjax_url=mathjax_url,
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
            target = folder / page.href
            target.write_text(html, encoding="utf-8")
            written.append(target)
        html, _ = exporter.from_notebook_node(
            _index_notebook(pages, code=code), {"metadata": {"name": "index"}})
        target = folder / "index.html"
        target.write_text(html, encoding="utf-8")
        written.append(target)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: build the handouts and list the files written."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("notebooks"),
                        help="folder of the source notebooks (default: notebooks)")
    parser.add_argument("--out", type=Path, default=Path("build/handouts"),
                        help="output folder (default: build/handouts); any other .html file "
                             f"directly in it or in its {PROSE_DIR}/ folder is deleted")
    parser.add_argument("--mathjax-url", default=DEFAULT_MATHJAX_URL,
                        help="where pages load MathJax from; '' for none (LaTeX shown as text)")
    args = parser.parse_args(argv)
    try:
        written = build_handouts(args.source, args.out, mathjax_url=args.mathjax_url)
    except (ValueError, HandoutBuildError) as error:
        return fail(error)
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
