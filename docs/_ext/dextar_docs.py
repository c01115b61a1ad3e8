"""dextar's Sphinx extension: the pages generated from the package when the docs are built.

* The config and CLI references (directives ``dextar-config-reference`` and
  ``dextar-cli-reference``), from the registries and the parser (:mod:`dextar_reference`).
* The API reference: one page per package (or top-level module) of ``dextar``
  (:func:`dextar_reference.api_pages`), written into ``reference/api/`` before the sources
  are read, so that a new module appears without a hand edit; the docstrings through autodoc
  and numpydoc (whose template this extension compiles once instead of once a docstring).
* The gallery and the figures of the guides: every example (``examples/*.toml`` through
  ``dextar run``, ``dextar program`` or ``dextar design``, ``examples/*.py`` as a script)
  and the runs that ``conf.py`` names in ``dextar_runs`` are run into
  ``<build>/gallery/NAME/`` while the sources are read (two at a time); the pages show their figures and what they printed
  (directives ``dextar-gallery``, ``dextar-figure``, ``dextar-output``). A run whose
  inputs and package are unchanged since the last build is not run again. A run that fails
  is a warning (so an error under ``-W``).
"""

from __future__ import annotations

import hashlib
import html
import importlib
import inspect
import os
import subprocess
import sys
import threading
import tomllib
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import dextar_reference
from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

logger = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

# -- the references -------------------------------------------------------------------------


class _Generated(SphinxDirective):
    """Parse generated reStructuredText in place (sections allowed)."""

    def generated(self) -> str:
        raise NotImplementedError

    def run(self) -> list[nodes.Node]:
        """The directive\'s nodes."""
        node = nodes.section()  # a container whose children take the document's levels
        node.document = self.state.document
        lines = StringList(self.generated().splitlines(), source="<generated>")
        nested_parse_with_titles(self.state, lines, node)
        return node.children


class ConfigReference(_Generated):
    """Every config table and key, from the registries."""

    def generated(self) -> str:
        """The reference's text."""
        return dextar_reference.config_reference()


class CliReference(_Generated):
    """Every command and argument, from the parser."""

    def generated(self) -> str:
        """The reference's text."""
        return dextar_reference.cli_reference()


# -- the API reference ----------------------------------------------------------------------


def write_api_pages(app: Sphinx) -> None:
    """Write the API pages into ``reference/api/`` (a file unchanged is not touched, so an
    incremental build reads only what changed); pages of modules gone are removed."""
    folder = Path(app.srcdir) / "reference" / "api"
    folder.mkdir(parents=True, exist_ok=True)
    pages = dextar_reference.api_pages()
    for name, content in pages.items():
        path = folder / f"{name}.rst"
        if not path.exists() or path.read_text() != content:
            path.write_text(content)
    for path in folder.glob("*.rst"):
        if path.stem not in pages:
            path.unlink()


def skip_member(app: Sphinx, what: str, name: str, obj: Any, skip: bool,
                options: Any) -> bool | None:
    """Leave out of the API pages what dextar does not define: imported names of other
    libraries and type aliases (``Region = tuple[...]``), which autodoc cannot sign."""
    if what == "module" and not (inspect.isclass(obj) or inspect.isfunction(obj)
                                 or inspect.ismodule(obj)):
        origin = getattr(obj, "__origin__", None)
        if origin is not None:  # a typing alias
            return True
    if inspect.isclass(obj) or inspect.isfunction(obj):
        mod = getattr(obj, "__module__", "") or ""
        if what == "module" and not mod.startswith("dextar"):
            return True
    return None


def resolve_reexport(app: Sphinx, env: Any, node: Any, contnode: nodes.Element) -> Any:
    """A reference to a name a package re-exports (``dextar.program.plan_program``) goes to
    where it is documented (``dextar.program.plan.plan_program``). A Python reference of a
    hand-written page that resolves nowhere is a warning (so an error under ``-W``); the
    docstrings' references to other libraries' types stay plain text."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"]
    found = None
    if target.startswith("dextar."):
        where, _, name = target.rpartition(".")
        try:
            package = importlib.import_module(where)
        except ImportError:
            package = None
        obj = getattr(package, name, None)
        if inspect.isclass(obj) or inspect.isfunction(obj):
            canonical: str | None = f"{obj.__module__}.{obj.__qualname__}"
        else:
            canonical = dextar_reference._defined_in(package, name) if package else None
        if canonical and canonical != target:
            found = env.get_domain("py").resolve_xref(env, node["refdoc"], app.builder,
                                                      node["reftype"], canonical, node,
                                                      contnode)
    if found is None and not node["refdoc"].startswith("reference/api/"):
        logger.warning("reference to %s found nowhere", target, location=node)
    return found


# -- numpydoc, with its template compiled once ------------------------------------------------


def _cache_numpydoc_template() -> None:
    """Numpydoc compiles its Jinja template for every docstring (3,000 times here, a fifth
    of the build); this gives it the template compiled once per builder."""
    try:
        from numpydoc import docscrape_sphinx as ds
        from numpydoc import numpydoc as nd
    except ImportError:
        return
    if not hasattr(ds, "get_doc_object_orig") or getattr(nd.get_doc_object, "_cached", False):
        return
    templates: dict[int, Any] = {}
    def get_doc_object(obj: Any, what: str | None = None, doc: Any = None,
                       config: dict[str, Any] | None = None, builder: Any = None) -> Any:
        config = {} if config is None else config
        if id(builder) not in templates:
            dirs = [os.path.join(os.path.dirname(ds.__file__), "templates")]
            if builder is None:  # (numpydoc's signature mangling asks without a builder)
                loader: Any = ds.FileSystemLoader(dirs)
            else:
                loader = ds.BuiltinTemplateLoader()
                loader.init(builder, dirs=dirs)
            env = ds.SandboxedEnvironment(loader=loader)
            templates[id(builder)] = env.get_template("numpydoc_docstring.rst")
        config["template"] = templates[id(builder)]
        return ds.get_doc_object_orig(obj, what=what, doc=doc, config=config,
                                      class_doc=ds.SphinxClassDoc,
                                      func_doc=ds.SphinxFunctionDoc,
                                      obj_doc=ds.SphinxObjDoc)

    get_doc_object._cached = True  # type: ignore[attr-defined]
    nd.get_doc_object = get_doc_object


# -- the runs: examples and the guides' figures ------------------------------------------------


@dataclass
class Run:
    """A command or script run into ``<build>/gallery/NAME``.

    Attributes
    ----------
    name : str
        Its folder and the name pages use.
    argv : list of str
        ``["dextar", ...]`` (``--out`` and ``--force`` added) or ``["python", script]``.
    shown : str
        The output folder as the page says it (the absolute build path is replaced by it).
    source : Path, optional
        The example file (shown in the gallery).
    title : str
        One line: the example's first comment or docstring line.
    """

    name: str
    argv: list[str]
    shown: str
    source: Path | None = None
    title: str = ""
    out: Path = field(default_factory=Path)
    future: Future[tuple[int, str, str]] | None = None

    @property
    def command(self) -> str:
        """The command line as a user types it."""
        if self.argv[0] == "python":
            return " ".join(["python", *self.argv[1:]])
        return " ".join([*self.argv, "--out", self.shown])


def _title(path: Path) -> str:
    lines = path.read_text().splitlines()
    if path.suffix == ".py":
        doc = inspect.cleandoc(path.read_text().split('"""')[1]) if '"""' in lines[0] else ""
        return doc.splitlines()[0] if doc else path.stem
    for ln in lines:
        if ln.startswith("#"):
            return ln.lstrip("# ").strip()
    return path.stem


def example_runs() -> list[Run]:
    """A run per example: a task file with ``[design]`` a design sweep of 8 designs on one
    worker, one with moves a program, any other config a run; a script runs as it is."""
    runs = []
    for path in sorted(EXAMPLES.glob("*.py")):
        runs.append(Run(path.stem, ["python", f"examples/{path.name}"], "", path,
                        _title(path)))
    for path in sorted(EXAMPLES.glob("*.toml")):
        raw = tomllib.loads(path.read_text())
        if "design" in raw:  # a design task: a small sweep of it (the whole one is minutes)
            argv = ["dextar", "design", f"examples/{path.name}", "--samples", "8",
                    "--workers", "1"]
        else:
            argv = ["dextar", "program" if "move" in raw or "program" in raw else "run",
                    f"examples/{path.name}"]
        runs.append(Run(path.stem, argv, f"{path.stem}/", path, _title(path)))
    return runs


def _fingerprint() -> str:
    """The installed package's files (names, sizes, times): a run of unchanged inputs on an
    unchanged package is not run again."""
    import dextar

    h = hashlib.sha256()
    base = Path(dextar.__file__).parent
    for p in sorted(base.rglob("*")):
        if p.is_file() and "__pycache__" not in p.parts:
            st = p.stat()
            h.update(f"{p.relative_to(base)} {st.st_size} {st.st_mtime_ns}\n".encode())
    return h.hexdigest()


def _execute(run: Run, stamp: str) -> tuple[int, str, str]:
    stamp_file = run.out / ".stamp"
    if stamp_file.exists() and stamp_file.read_text() == stamp:
        return 0, (run.out / ".stdout").read_text(), ""
    run.out.mkdir(parents=True, exist_ok=True)
    if run.argv[0] == "python":
        argv = [sys.executable, *run.argv[1:]]
    else:
        argv = [sys.executable, "-m", "dextar", *run.argv[1:], "--out", str(run.out),
                "--force"]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, env=env,
                          timeout=600)
    stdout = proc.stdout.replace(str(run.out), run.shown.rstrip("/") or ".")
    (run.out / ".stdout").write_text(stdout)
    if proc.returncode == 0:
        stamp_file.write_text(stamp)
    elif stamp_file.exists():
        stamp_file.unlink()
    return proc.returncode, stdout, proc.stderr


def start_runs(app: Sphinx) -> None:
    """Start every run (two at a time) while the sources are read."""
    if app.builder.format != "html":  # (the pages show the runs' files as HTML)
        return
    runs = {r.name: r for r in example_runs()}
    for name, (argv, shown) in app.config.dextar_runs.items():
        runs[name] = Run(name, list(argv), shown)
    fingerprint = _fingerprint()
    pool = ThreadPoolExecutor(max_workers=2, thread_name_prefix="dextar-docs-run")
    for run in sorted(runs.values(), key=lambda r: r.argv[0] != "python"):  # scripts first
        run.out = Path(app.outdir) / "gallery" / run.name
        src = run.source.read_text() if run.source else ""
        stamp = hashlib.sha256(f"{run.argv}\n{src}\n{fingerprint}".encode()).hexdigest()
        run.future = pool.submit(_execute, run, stamp)
    pool.shutdown(wait=False)
    app._dextar_runs = runs  # type: ignore[attr-defined]
    app._dextar_checked = set()  # type: ignore[attr-defined]
    app._dextar_lock = threading.Lock()  # type: ignore[attr-defined]


def finished(app: Sphinx, name: str) -> Run | None:
    """The run ``name``, waited for (a failure warned once); None if there is none."""
    runs: dict[str, Run] = getattr(app, "_dextar_runs", {})
    run = runs.get(name)
    if run is None or run.future is None:
        return None
    code, _, stderr = run.future.result()
    with app._dextar_lock:  # type: ignore[attr-defined]
        if code != 0 and name not in app._dextar_checked:  # type: ignore[attr-defined]
            logger.warning("docs run %r (%s) failed with exit status %d: %s", name,
                           run.command, code, stderr.strip()[-2000:])
        app._dextar_checked.add(name)  # type: ignore[attr-defined]
    return run


def check_runs(app: Sphinx, exc: Exception | None) -> None:
    """Every run waited for and its failure said, even one no page shows."""
    for name in getattr(app, "_dextar_runs", {}):
        finished(app, name)


class RunPlaceholder(nodes.General, nodes.Element):
    """A placeholder for what a run made, filled when the page is written (the runs go on
    while the sources are read)."""


def _figure_html(src: str, href: str, caption: str) -> str:
    cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
    return (f'<figure class="dextar-figure"><a href="{html.escape(href)}">'
            f'<img src="{html.escape(src)}" alt="{html.escape(caption or src)}" '
            f'loading="lazy"></a>{cap}</figure>')


def fill_runs(app: Sphinx, doctree: nodes.document, docname: str) -> None:
    """Replace each placeholder by the run's figures or printed text."""
    up = "../" * docname.count("/")
    for node in list(doctree.findall(RunPlaceholder)):
        if app.builder.format != "html":
            node.replace_self([])
            continue
        run = finished(app, node["run"])
        if run is None:
            logger.warning("no docs run named %r", node["run"], location=node)
            node.replace_self([])
            continue
        new: list[nodes.Node] = []
        if node["what"] == "figure":
            for file, _ in node["files"]:
                if not (run.out / file).exists():
                    logger.warning("docs run %r wrote no %s", run.name, file, location=node)
                    continue
                src = f"{up}gallery/{run.name}/{file}"
                figure = nodes.container(classes=["dextar-figure"])
                figure += nodes.raw("", _figure_html(src, src, ""), format="html")
                figure += node.children  # the caption, parsed
                new.append(figure)
        elif node["what"] == "figures":  # every PNG the run wrote, linked to its report
            report = run.out / "report.html"
            pngs = sorted(run.out.glob("*.png"))
            cells = "".join(
                _figure_html(f"{up}gallery/{run.name}/{p.name}",
                             f"{up}gallery/{run.name}/"
                             f"{'report.html' if report.exists() else p.name}", p.stem)
                for p in pngs)
            if cells:
                new.append(nodes.raw("", f'<div class="dextar-gallery">{cells}</div>',
                                     format="html"))
            if report.exists():
                href = f"{up}gallery/{run.name}/report.html"
                files = sorted(p.name for p in run.out.iterdir()
                               if not p.name.startswith("."))
                new.append(nodes.raw("", f'<p>The run\'s <a href="{href}">report</a> and '
                                     f'its files: {html.escape(", ".join(files))}.</p>',
                                     format="html"))
        else:  # what it printed
            text = (run.out / ".stdout").read_text() if (run.out / ".stdout").exists() else ""
            new.append(nodes.literal_block(text, text.rstrip("\n"), language="text"))
        node.replace_self(new)


def _placeholder(run: str, what: str,
                 files: list[tuple[str, str]] | None = None) -> RunPlaceholder:
    node = RunPlaceholder()
    node["run"], node["what"], node["files"] = run, what, files or []
    return node


def _note_runs(env: Any) -> None:
    """The page being read shows what a run made: it is read again at every build (what a
    run prints changes with the package, not with the page)."""
    if not hasattr(env, "dextar_run_docs"):
        env.dextar_run_docs = set()
    env.dextar_run_docs.add(env.docname)


def outdated_runs(app: Sphinx, env: Any, added: set[str], changed: set[str],
                  removed: set[str]) -> list[str]:
    """The pages that show runs, to be read and written again."""
    return sorted(getattr(env, "dextar_run_docs", set()) - removed)


def purge_runs(app: Sphinx, env: Any, docname: str) -> None:
    """Forget a page that is read again (it notes itself again)."""
    getattr(env, "dextar_run_docs", set()).discard(docname)


def merge_runs(app: Sphinx, env: Any, docnames: set[str], other: Any) -> None:
    """Parallel reading: the pages the other process noted."""
    if not hasattr(env, "dextar_run_docs"):
        env.dextar_run_docs = set()
    env.dextar_run_docs |= getattr(other, "dextar_run_docs", set()) & docnames


class RunFigure(SphinxDirective):
    """``.. dextar-figure:: RUN FILE`` with the caption as content: a figure a run wrote."""

    required_arguments = 2
    has_content = True

    def run(self) -> list[nodes.Node]:
        """The directive\'s nodes."""
        _note_runs(self.env)
        node = _placeholder(self.arguments[0], "figure", [(self.arguments[1], "")])
        caption = nodes.paragraph(classes=["dextar-caption"])
        caption += self.parse_inline(" ".join(self.content), lineno=self.lineno)[0]
        node += caption
        return [node]


class RunOutput(SphinxDirective):
    """``.. dextar-output:: RUN``: what a run printed."""

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        """The directive\'s nodes."""
        _note_runs(self.env)
        return [_placeholder(self.arguments[0], "text")]


class Gallery(SphinxDirective):
    """``.. dextar-gallery::``: every example with its command, its file, what it printed
    and its figures."""

    def run(self) -> list[nodes.Node]:
        """The directive\'s nodes."""
        _note_runs(self.env)
        out: list[nodes.Node] = []
        for run in example_runs():
            assert run.source is not None
            section = nodes.section(ids=[f"example-{run.name}"])
            section += nodes.title("", run.source.name)
            section += nodes.paragraph("", run.title)
            section += nodes.paragraph("", "", nodes.Text("Run: "),
                                       nodes.literal("", run.command))
            self.env.note_dependency(str(run.source))
            code = run.source.read_text()
            block = nodes.literal_block(code, code,
                                        language="python" if run.source.suffix == ".py"
                                        else "toml")
            section += nodes.container("", nodes.caption("", run.source.name), block,
                                       classes=["literal-block-wrapper"], literal_block=True)
            section += nodes.paragraph("", "It prints:")
            section += _placeholder(run.name, "text")
            if run.argv[0] != "python":
                section += _placeholder(run.name, "figures")
            out.append(section)
        return out


def setup(app: Sphinx) -> dict[str, Any]:
    """Register the directives, the API pages, the runs and numpydoc's template cache."""
    app.setup_extension("sphinx.ext.autodoc")
    app.setup_extension("numpydoc")
    _cache_numpydoc_template()
    app.add_config_value("dextar_runs", {}, "env")
    app.add_directive("dextar-config-reference", ConfigReference)
    app.add_directive("dextar-cli-reference", CliReference)
    app.add_directive("dextar-gallery", Gallery)
    app.add_directive("dextar-figure", RunFigure)
    app.add_directive("dextar-output", RunOutput)
    app.add_node(RunPlaceholder)
    app.connect("builder-inited", write_api_pages)
    app.connect("builder-inited", start_runs)
    app.connect("autodoc-skip-member", skip_member)
    app.connect("missing-reference", resolve_reexport)
    app.connect("doctree-resolved", fill_runs)
    app.connect("env-get-outdated", outdated_runs)
    app.connect("env-purge-doc", purge_runs)
    app.connect("env-merge-info", merge_runs)
    app.connect("build-finished", check_runs)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": False}
