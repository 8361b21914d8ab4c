"""Every fenced code block of README.md and docs/*.md runs as written.

The blocks of one document run in order, in a fresh temporary folder holding a link to the
repository's ``examples/`` (so a command may name ``examples/…`` and a block may write
files), sharing one Python namespace:

- ``python``: executed; a traceback names the document and its line;
- ``bash``, ``sh``: run by ``bash -e -o pipefail`` with the installed ``splinedeform`` first
  on ``PATH``; ``console``: the lines starting with ``$ `` are run that way;
- ``json``: parsed;
- ``toml``: read as a scenario (validated and its surface built) when it has a
  ``[surface]`` table, otherwise only parsed;
- ``text``: shown output, not run.

A block that must not run (it installs a virtual environment, or runs this very suite) is
preceded by ``<!-- skip-test: reason -->`` on the line before its opening fence. A block
without a language, or with another one, fails: whoever adds a block says what it is.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

RUN = ("python", "bash", "sh", "console", "toml", "json")
SHOWN = ("text",)
SKIP = re.compile(r"<!--\s*skip-test:\s*(?P<reason>.*?)\s*-->")
FENCE = re.compile(r"^(?P<indent> *)```(?P<lang>[\w+-]*)\s*$")

#: at most this many blocks may be skipped over all documents, each with its reason: the
#: README's make commands (they install a virtual environment and run this suite) and
#: docs/sculpt.md's commands (they start a server that runs until stopped)
MAX_SKIPPED = 2


@dataclass
class Block:
    document: Path
    line: int          # 1-based line of the opening fence
    lang: str
    code: str
    skip: str | None   # the reason given by a skip-test marker

    @property
    def where(self) -> str:
        return f"{self.document.relative_to(ROOT)}:{self.line}"


def code_blocks(document: Path) -> list[Block]:
    """The fenced blocks of a Markdown file, with the skip-test reason before each."""
    lines = document.read_text(encoding="utf-8").splitlines()
    blocks, i = [], 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if opening is None:
            i += 1
            continue
        indent = len(opening["indent"])
        end = i + 1
        while end < len(lines) and lines[end].strip() != "```":
            end += 1
        assert end < len(lines), f"{document.name}:{i + 1}: code block never closed"
        before = lines[i - 1] if i > 0 else ""
        marker = SKIP.search(before)
        blocks.append(Block(document, i + 1, opening["lang"],
                            "\n".join(line[indent:] for line in lines[i + 1:end]) + "\n",
                            marker["reason"] if marker else None))
        i = end + 1
    return blocks


ALL_BLOCKS = [block for document in DOCUMENTS for block in code_blocks(document)]


def test_every_block_says_its_language_and_skips_are_few_and_justified():
    untagged = [b.where for b in ALL_BLOCKS if b.lang not in RUN + SHOWN]
    assert not untagged, f"code blocks without a known language ({RUN + SHOWN}): {untagged}"
    skipped = [b for b in ALL_BLOCKS if b.skip is not None]
    assert all(b.skip for b in skipped), "a skip-test marker without a reason"
    assert len(skipped) <= MAX_SKIPPED, [f"{b.where}: {b.skip}" for b in skipped]
    assert len([b for b in ALL_BLOCKS if b.lang in RUN and b.skip is None]) >= 10


def test_markers_stand_right_before_a_block():
    for document in DOCUMENTS:
        lines = document.read_text(encoding="utf-8").splitlines()
        for n, line in enumerate(lines, start=1):
            if SKIP.search(line):
                assert n < len(lines) and FENCE.match(lines[n]), \
                    f"{document.name}:{n}: skip-test marker not followed by a code block"


def _shell(block: Block, folder: Path) -> None:
    code = block.code
    if block.lang == "console":
        code = "\n".join(line[2:] for line in code.splitlines() if line.startswith("$ ")) + "\n"
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
           "MPLBACKEND": "Agg"}
    done = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", code], cwd=folder, env=env,
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, (f"{block.where}: exit code {done.returncode}\n{code}\n"
                                  f"--- stdout\n{done.stdout[-3000:]}\n"
                                  f"--- stderr\n{done.stderr[-3000:]}")


def _toml(block: Block, folder: Path) -> None:
    from splinedeform.scenario import build, parse_scenario

    try:
        table = tomllib.loads(block.code)
    except tomllib.TOMLDecodeError as exc:
        pytest.fail(f"{block.where}: not TOML: {exc}")
    if "surface" in table:
        build(parse_scenario(block.code, source=block.where, directory=folder))


def _json(block: Block) -> None:
    try:
        json.loads(block.code)
    except json.JSONDecodeError as exc:
        pytest.fail(f"{block.where}: not JSON: {exc}")


def _python(block: Block, namespace: dict[str, object]) -> None:
    # padded so that a traceback's line numbers are the document's
    source = "\n" * block.line + block.code
    exec(compile(source, str(block.document), "exec"), namespace)


@pytest.mark.parametrize("document", sorted({b.document for b in ALL_BLOCKS if b.lang in RUN}),
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_code_blocks_run(document, tmp_path, monkeypatch):
    blocks = [b for b in code_blocks(document) if b.lang in RUN]
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict[str, object] = {"__name__": "__main__"}
    for block in blocks:
        if block.skip is not None:
            continue
        if block.lang == "python":
            _python(block, namespace)
        elif block.lang == "toml":
            _toml(block, tmp_path)
        elif block.lang == "json":
            _json(block)
        else:
            _shell(block, tmp_path)


def test_every_example_file_named_in_the_docs_exists():
    """Inline mentions too (``splinedeform run examples/….toml`` in the gallery)."""
    for document in DOCUMENTS:
        text = document.read_text(encoding="utf-8")
        for name in set(re.findall(r"examples/([\w.-]+\.toml)", text)):
            assert (ROOT / "examples" / name).is_file(), \
                f"{document.relative_to(ROOT)} names examples/{name}, which does not exist"
