"""How a handout page looks and reads: offline maths, described figures, accessible markup.

:func:`handout_exporter` is the nbconvert ``HTMLExporter`` (lab template) that renders one
notebook as a handout page (with links to another notebook of the pack pointed at its
page); :func:`mathjax_files` lists the MathJax files the pages load, which the build copies
once into the handouts folder (``mathjax/``), so the pages typeset their equations with no
network and no third-party script.

Maths: MathJax 2.7 as shipped in the ``jupyter-server-mathjax`` wheel (the copy Jupyter's
own tools serve), TeX input with the AMS extensions, SVG output. SVG output draws glyphs
from JavaScript font files loaded with ``<script>`` tags, so it needs no web-font download:
a browser that refuses fonts from ``file:`` URLs in another folder (Firefox's file-origin
rule) still shows every equation. The AssistiveMML extension puts a MathML copy of each
equation beside the picture for screen readers. Only the files these pages can load are
copied (:data:`MATHJAX_PARTS`).

Figures: a figure shown with :func:`lqe_helpers.plotting.show_figure` arrives as an
``<img>`` whose ``alt`` is its description (``text/html``, preferred) and as ``image/png``
with the description in ``metadata["image/png"]["alt"]``, which the page's template
(``handout_template/lqe_handout.html.j2``, with its CSS and MathJax configuration beside
it) writes into the ``alt`` attribute (nbconvert's lab template drops it). A PNG output with no
description gets nbconvert's :data:`GENERIC_ALT`, which the browser audit refuses;
:func:`undescribed_figures` lists such figures for the build to report.

Markup: colours of code, prompts and links raised to WCAG 2.1 AA contrast (4.5:1), a
visible focus ring, no "¶" anchor links (link text that says nothing), and a layout that
reflows at 320 CSS px: text wraps; code blocks, wide tables and wide equations scroll in
their own box.
"""

from __future__ import annotations

import base64
import binascii
import io
import re
from collections.abc import Sequence
from pathlib import Path

import nbformat
from nbconvert.exporters import HTMLExporter
from nbconvert.preprocessors import Preprocessor
from PIL import Image, UnidentifiedImageError
from traitlets import List, Unicode
from traitlets.config import Config

#: Folder of the MathJax copy inside the handouts folder.
MATHJAX_DIR = "mathjax"
#: MathJax's combined configuration the pages load (TeX input; HTML-CSS and native MathML
#: output jax included in the one file).
MATHJAX_CONFIG_NAME = "TeX-AMS-MML_HTMLorMML-full"
#: Files and folders of the MathJax distribution the pages can load, relative to its
#: root (``jupyter_server_mathjax/static``): the loader, the combined configuration, the
#: MathML element jax, the TeX and accessibility extensions, the HTML-CSS output's
#: STIX-Web font data and web fonts (the only font the wheel ships), and the licence.
MATHJAX_PARTS = (
    "LICENSE",
    "MathJax.js",
    f"config/{MATHJAX_CONFIG_NAME}.js",
    "jax/element/mml",
    "jax/output/HTML-CSS/autoload",
    "jax/output/HTML-CSS/fonts/STIX-Web",
    "fonts/HTML-CSS/STIX-Web/woff",
    "extensions/AssistiveMML.js",
    "extensions/MathEvents.js",
    "extensions/MathZoom.js",
    "extensions/toMathML.js",
    "extensions/TeX",
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
#: The alt text nbconvert gives an image that has none: a page must never show it.
GENERIC_ALT = "No description has been provided for this image"
#: The mimetypes a figure arrives as, and whose description (``alt``) a page needs.
FIGURE_MIMETYPES = ("image/png", "image/jpeg")

#: The handout page's template (extending nbconvert's lab template), with its CSS and
#: MathJax configuration beside it.
TEMPLATE_DIR = Path(__file__).with_name("handout_template")
_TEMPLATE_NAME = "lqe_handout.html.j2"


def mathjax_root() -> Path:
    """The MathJax distribution shipped in the ``jupyter-server-mathjax`` wheel."""
    import jupyter_server_mathjax

    return Path(jupyter_server_mathjax.__file__).parent / "static"


def mathjax_files(root: Path | None = None) -> dict[str, Path]:
    """The MathJax files a handout folder needs, by their path inside ``mathjax/``.

    Parameters
    ----------
    root : Path, optional
        Root of the MathJax distribution (default :func:`mathjax_root`).

    Returns
    -------
    dict of str to Path
        ``"jax/output/SVG/jax.js"`` (POSIX path relative to :data:`MATHJAX_DIR`) →
        the file to copy, for every file of :data:`MATHJAX_PARTS`, sorted.

    Raises
    ------
    FileNotFoundError
        If a part is missing from ``root`` (a MathJax copy of another layout).
    """
    root = mathjax_root() if root is None else Path(root)
    files = {}
    for part in MATHJAX_PARTS:
        path = root / part
        if path.is_file():
            files[part] = path
        elif path.is_dir():
            files.update({found.relative_to(root).as_posix(): found
                          for found in path.rglob("*") if found.is_file()})
        else:
            raise FileNotFoundError(f"MathJax part {part!r} is missing from {root}")
    return dict(sorted(files.items()))


def mathjax_url(depth: int = 0) -> str:
    """The relative URL that loads the local MathJax from a page ``depth`` folders down.

    ``0`` for a page beside ``mathjax/``
    (``mathjax/MathJax.js?config=TeX-AMS-MML_HTMLorMML-full``), ``1`` for a page in
    ``prose/`` (``../mathjax/MathJax.js?config=…``).
    """
    if isinstance(depth, bool) or not isinstance(depth, int) or depth < 0:
        raise ValueError(f"depth must be a whole number >= 0, got {depth!r}")
    return "../" * depth + f"{MATHJAX_DIR}/MathJax.js?config={MATHJAX_CONFIG_NAME}"


def figure_description(output: nbformat.NotebookNode | dict) -> str | None:
    """The description a figure output carries for its page, or ``None``.

    ``metadata[mimetype]["alt"]`` (what :func:`lqe_helpers.plotting.show_figure` writes)
    for a PNG or JPEG output, stripped; ``None`` if it is missing or blank. An output
    shown as ``text/html`` (an ``<img alt>`` of its own) is not a bare figure: ``None``.
    """
    data = output.get("data", {})
    metadata = output.get("metadata", {})
    for mimetype in FIGURE_MIMETYPES:
        if mimetype in data:
            alt = (metadata.get(mimetype) or {}).get("alt") or metadata.get("alt")
            return alt.strip() if isinstance(alt, str) and alt.strip() else None
    return None


def undescribed_figures(notebook: nbformat.NotebookNode) -> list[str]:
    """Where ``notebook`` shows a figure its page cannot describe: ``"cell N"`` per figure.

    A figure is a display output that the page shows as a picture (PNG or JPEG, no
    ``text/html`` before it in :data:`DISPLAY_PRIORITY`) with no description in its
    metadata. ``N`` counts every cell (markdown included) from 0.
    """
    found = []
    for index, cell in enumerate(notebook.cells):
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            shown = next((mime for mime in DISPLAY_PRIORITY if mime in data), None)
            if shown in FIGURE_MIMETYPES and figure_description(output) is None:
                found.append(f"cell {index}")
    return found


def png_fault(text: object) -> str | None:
    """What is wrong with an ``image/png`` output's data (base64 text), or ``None``.

    Not text, not base64, no bytes, not a PNG (Pillow reads and verifies it: its
    signature and the checksum of every chunk), or a picture of zero width or height.
    """
    try:
        data = base64.b64decode("".join(text.split()), validate=True)
    except (AttributeError, binascii.Error, ValueError):
        return "its data is not base64 text"
    if not data:
        return "it is empty (0 bytes)"
    try:
        with Image.open(io.BytesIO(data), formats=["PNG"]) as image:
            size = image.size
            image.verify()
    except UnidentifiedImageError:
        return f"its {len(data)} bytes are not a PNG"
    except (OSError, SyntaxError, ValueError) as error:
        return f"its {len(data)} bytes are not a valid PNG ({error})"
    return None if min(size) > 0 else f"it is {size[0]}×{size[1]} pixels"


def broken_pngs(notebook: nbformat.NotebookNode) -> list[str]:
    """Where ``notebook`` shows an ``image/png`` output its page could not show:
    ``"cell N: <what is wrong>"`` per output (:func:`png_fault`); ``N`` counts every
    cell (markdown included) from 0."""
    return [f"cell {index}: {fault}" for index, cell in enumerate(notebook.cells)
            for output in cell.get("outputs", [])
            if "image/png" in output.get("data", {})
            and (fault := png_fault(output["data"]["image/png"])) is not None]


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


def handout_exporter(*, code: bool = True, mathjax_url: str = "",
                     stems: Sequence[str] = ()) -> HTMLExporter:
    """The HTML exporter for handout pages.

    Parameters
    ----------
    code : bool
        Show the code cells' source (``False`` for the prose variant: markdown,
        printed results and figures only, without prompts).
    mathjax_url : str
        URL that loads MathJax (``async``) as the page sees it, configuration query
        included: :func:`mathjax_url` for the local copy; ``""`` (default) leaves
        MathJax out, and the equations show as their LaTeX source.
    stems : sequence of str
        File stems of the notebooks that get a page next to this one; markdown links
        to ``<stem>.ipynb`` are pointed at ``<stem>.html`` (:class:`NotebookLinkPreprocessor`).

    Returns
    -------
    HTMLExporter
        Lab template with the handout's overrides; ``resources`` passed to
        ``from_notebook_node`` may carry ``lqe_nav`` (``index``, ``previous``,
        ``next``: links of the page navigation).
    """
    config = Config()
    config.NbConvertBase.display_data_priority = list(DISPLAY_PRIORITY)
    config.HTMLExporter.embed_images = True
    config.HTMLExporter.mathjax_url = mathjax_url
    config.HTMLExporter.exclude_anchor_links = True
    config.HTMLExporter.language_code = "en"
    config.TagRemovePreprocessor.enabled = True
    config.TagRemovePreprocessor.remove_cell_tags = {"remove-cell"}
    config.TagRemovePreprocessor.remove_input_tags = {"remove-input"}
    config.TagRemovePreprocessor.remove_all_outputs_tags = {"remove-output"}
    if not code:
        config.TemplateExporter.exclude_input = True
        config.TemplateExporter.exclude_input_prompt = True
        config.TemplateExporter.exclude_output_prompt = True
    exporter = HTMLExporter(config=config, template_name="lab",
                            extra_template_paths=[str(TEMPLATE_DIR)])
    exporter.template_file = _TEMPLATE_NAME
    exporter.register_preprocessor(NotebookLinkPreprocessor(stems=list(stems)), enabled=True)
    return exporter


def mathjax_copy(root: Path | None = None) -> dict[str, bytes]:
    """The MathJax copy for a handouts folder: ``"mathjax/…"`` → file content.

    Every file of :func:`mathjax_files` under :data:`MATHJAX_DIR`, for the build to
    write with its pages (about 1.9 MB: see :func:`mathjax_files`).
    """
    return {f"{MATHJAX_DIR}/{name}": path.read_bytes()
            for name, path in mathjax_files(root).items()}
