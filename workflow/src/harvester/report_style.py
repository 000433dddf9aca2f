"""The one look of the project's HTML pages (the diagnosis's summary.html, the benchmark
page): the style sheet and the page around a body. Plain strings, no imports from any layer,
so that every layer's pages can share it."""

from __future__ import annotations

import html
from typing import Any

STYLE = ("body{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222}"
         ".headline{font-size:1.25em;padding:.6em;border-left:.4em solid #555;background:#f4f4f4}"
         "figure{margin:1em 0}img{max-width:100%}figcaption{color:#555;font-size:.9em}"
         "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.2em .6em}")


def esc(x: Any) -> str:
    """``x`` as HTML text."""
    return html.escape(str(x))


def page(title: str, body: str) -> str:
    """A self-contained page: ``title`` as its title and first heading, then ``body``
    (HTML), in :data:`STYLE`."""
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{esc(title)}</title>"
            f"<style>{STYLE}</style></head><body><h1>{esc(title)}</h1>{body}</body></html>\n")
