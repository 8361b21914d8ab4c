"""report.md keeps no link whose scheme is not http, https or mailto (or relative).

report.md is rendered by a CommonMark renderer independent of the writer (markdown-it-py,
with its own link filter switched off, as a permissive renderer would be) and every
``href``/``src`` it produces is read the way a browser's URL parser reads a scheme.
"""

from __future__ import annotations

import re

import pytest

from splinedeform.export import report_markdown
from splinedeform.export.report import defuse_links

markdown_it = pytest.importorskip("markdown_it", reason="markdown-it-py renders report.md")

HOSTILE = [
    "[click](javascript:alert(1))",
    "[click](JaVaScRiPt:alert(1))",
    "[click]( javascript:alert(1) )",
    "[click](java\tscript:alert(1))",
    "[click](\x01javascript:alert(1))",
    "[click](javascript\\:alert(1))",
    "[click](<javascript:alert(1)>)",
    "[click](javascript&#58;alert(1))",
    "![img](data:text/html;base64,PHNjcmlwdD5hbGVydCgxKTwvc2NyaXB0Pg==)",
    "[click](vbscript:msgbox(1))",
    "[click](file:///etc/passwd)",
    "<javascript:alert(1)>",                           # autolink
    "<data:text/html,<script>alert(1)</script>>",
    "[click][r] [r]: javascript:alert(1)",              # reference link and definition
    "[r] [r]: data:text/html,x",
]
SAFE = {"[site](https://example.org/a?b=1)": "https://example.org/a?b=1",
        "[mail](mailto:someone@example.org)": "mailto:someone@example.org",
        "[doc](docs/sculpt.md)": "docs/sculpt.md"}


def _renderer():
    md = markdown_it.MarkdownIt("commonmark").enable("table")
    md.validateLink = lambda url: True          # let every link through: we check them
    return md


def _scheme(url: str) -> str | None:
    """The scheme a browser reads (WHATWG URL: leading/trailing C0 and space stripped,
    tab and newline removed anywhere), lower case; None for a relative URL."""
    url = url.strip("".join(map(chr, range(0x21)))).replace("\t", "").replace("\n", "")
    url = url.replace("\r", "")
    match = re.match(r"([A-Za-z][A-Za-z0-9+.\-]*):", url)
    return match.group(1).lower() if match else None


def _links(markdown: str) -> list[str]:
    """Every href and src of the rendered markdown (decoded as a browser sees them)."""
    import html

    rendered = _renderer().render(markdown)
    found = re.findall(r'(?:href|src)="([^"]*)"', rendered)
    return [html.unescape(u) for u in found]


@pytest.mark.parametrize("text", HOSTILE)
def test_no_unsafe_link_survives_in_a_description(text):
    report = {"inputs": {"description": text, "title": text}}
    markdown = report_markdown(report, title=text)
    schemes = {_scheme(url) for url in _links(markdown)}
    assert schemes <= {None, "http", "https", "mailto"}, (markdown, schemes)
    # neither is the dangerous scheme left readable as text a renderer might link
    lowered = markdown.lower()
    for bad in ("javascript:", "vbscript:", "data:", "file:"):
        assert bad not in lowered, markdown


@pytest.mark.parametrize("text, url", SAFE.items())
def test_safe_and_relative_links_are_kept(text, url):
    markdown = report_markdown({"inputs": {"description": text}})
    assert url in _links(markdown)


def test_a_reference_definition_at_the_start_of_a_line_is_defused():
    """Cells are one line, so no definition can start a line there; the function defuses
    one that would (checked where a renderer honours it: text of several lines)."""
    text = "[click][r]\n\n[r]: javascript:alert(1)\n\n[s]: https://example.org\n\n[ok][s]"
    links = _links(defuse_links(text))
    assert links == ["https://example.org"], links
    assert _links(text)[0].startswith("javascript")     # the check sees the raw link


def test_text_with_colons_is_left_alone():
    text = "note: w10 = 1.0 [see](#modes); time: 2 s"
    assert defuse_links(text) == text
