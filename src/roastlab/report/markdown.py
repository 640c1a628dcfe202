"""A report written as Markdown (``fit-roaster``'s report.md), shown as HTML.

One renderer for the two places a roaster reads the report in a browser: ``report.html``, which
``fit-roaster`` writes beside report.md as one file that opens anywhere (its figures inside it), and
the page (``roastlab app``), which shows the same HTML in its "Fit report" panel. CommonMark with
tables (markdown-it-py); raw HTML in the text is shown as text, since a report quotes log names and
notes read from the logs; each picture the report draws is embedded from the PNG bytes given for its
file name, and a picture named otherwise is dropped.
"""

from __future__ import annotations

import base64
import html

from markdown_it import MarkdownIt

#: The page's look for a standalone report: tables ruled like the page's, figures at most the width.
_STYLE = (
    "body { font-family: system-ui, sans-serif; color: #222; max-width: 1100px; margin: 16px auto; padding: 0 12px; }"
    # a table wider than a phone scrolls in place rather than widening the page
    " table { border-collapse: collapse; font-size: 13px; margin: 6px 0; display: block; overflow-x: auto; }"
    " th, td { border-bottom: 1px solid #e5e5e5; padding: 2px 8px; text-align: right; }"
    " th:first-child, td:first-child { text-align: left; } th { background: #f2ece6; }"
    " img { max-width: 100%; } code { font-size: 12px; }"
)


def markdown_html(text: str, pictures: dict[str, bytes]) -> str:
    """``text`` (Markdown) as an HTML fragment. ``pictures``: PNG bytes by the file name the text
    links (``![held out](heldout.png)`` takes ``pictures["heldout.png"]``), embedded as data URLs;
    a picture whose name is not among them is dropped. Raw HTML in ``text`` is escaped."""
    md = MarkdownIt("commonmark", {"html": False}).enable("table")
    tokens = md.parse(text)
    for token in tokens:
        if token.children is None:
            continue
        kept = []
        for child in token.children:
            if child.type == "image":
                png = pictures.get(str(child.attrGet("src") or ""))
                if png is None:
                    continue
                child.attrSet("src", "data:image/png;base64," + base64.b64encode(png).decode())
            kept.append(child)
        token.children = kept
    return md.renderer.render(tokens, md.options, {})


def html_document(title: str, text: str, pictures: dict[str, bytes]) -> str:
    """A standalone HTML page of ``text`` (:func:`markdown_html`), titled ``title``, that needs no
    other file and no network, and fits a phone's screen as a desktop's."""
    return (
        '<!doctype html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{html.escape(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n"
        f"{markdown_html(text, pictures)}</body>\n</html>\n"
    )
