"""The frame of dextar's self-contained HTML pages: one style, figures inlined as data URIs,
tables of named values formatted alike."""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping, Sequence
from typing import Any

STYLE = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;"
         "color:#222}table{border-collapse:collapse;margin:0.5em 0 1.5em}"
         ".wide{display:block;overflow-x:auto;max-width:100%}"
         "td,th{border:1px solid #ccc;padding:3px 8px;text-align:left;font-size:14px}"
         "th{background:#eee}figure{margin:1.5em 0}img{max-width:100%}"
         ".holds{color:#060}.fails{color:#b00}.approximate{color:#a60}")


def page(title: str, body: str) -> str:
    """A complete HTML page with ``title`` (plain text, also the heading) and ``body``
    (HTML)."""
    t = html.escape(title)
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{t}</title>"
            f"<style>{STYLE}</style></head><body><h1>{t}</h1>{body}</body></html>\n")


def fmt(v: Any) -> str:
    """A value as a table cell: numbers to 6 significant digits (scientific outside
    [1e-3, 1e5)), lists joined by commas, mappings as ``key = value``; escaped."""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        if v == 0 or (1e-3 <= abs(v) < 1e5):
            return f"{v:.6g}"
        return f"{v:.3e}"
    if isinstance(v, (list, tuple)):
        return ", ".join(fmt(x) for x in v)
    if isinstance(v, Mapping):
        return "; ".join(f"{html.escape(str(k))} = {fmt(x)}" for k, x in v.items())
    return html.escape(str(v))


def table(rows: Sequence[tuple[str, Any]], head: tuple[str, str] = ("quantity", "value")
          ) -> str:
    """A two-column table of named values."""
    body = "".join(f"<tr><td>{html.escape(k)}</td><td>{fmt(v)}</td></tr>" for k, v in rows)
    return f"<table><tr><th>{head[0]}</th><th>{head[1]}</th></tr>{body}</table>"


def grid(head: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """A table of rows under ``head``, scrolled sideways when it is wider than the page."""
    h = "".join(f"<th>{html.escape(c)}</th>" for c in head)
    b = "".join("<tr>" + "".join(f"<td>{fmt(v)}</td>" for v in r) + "</tr>" for r in rows)
    return f"<table class='wide'><tr>{h}</tr>{b}</table>"


def image(data: bytes, alt: str, caption: str = "", mime: str = "image/png") -> str:
    """One inline image with its caption."""
    b64 = base64.b64encode(data).decode("ascii")
    cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
    return f"<figure><img alt='{html.escape(alt)}' src='data:{mime};base64,{b64}'>{cap}</figure>"


def figures(pngs: Mapping[str, bytes], captions: Mapping[str, str] | None = None) -> str:
    """The PNG images ``name -> bytes`` as inline ``<figure>`` elements."""
    caps = captions or {}
    return "".join(image(v, k, caps.get(k, "")) for k, v in pngs.items())
