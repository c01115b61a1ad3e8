"""The frame of dextar's self-contained HTML pages: one style, figures inlined as data URIs."""

from __future__ import annotations

import base64
import html

STYLE = ("body{font-family:sans-serif;max-width:960px;margin:2em auto}"
         "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;"
         "font-size:14px}img{max-width:100%}")


def page(title: str, body: str) -> str:
    """A complete HTML page with ``title`` (plain text) and ``body`` (HTML)."""
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>"
            f"{html.escape(title)}</title><style>{STYLE}</style></head><body>{body}"
            "</body></html>\n")


def figures(pngs: dict[str, bytes]) -> str:
    """The PNG images ``name -> bytes`` as inline ``<figure>`` elements."""
    return "".join(f"<figure><img alt='{html.escape(k)}' src='data:image/png;base64,"
                   f"{base64.b64encode(v).decode('ascii')}'></figure>" for k, v in pngs.items())
