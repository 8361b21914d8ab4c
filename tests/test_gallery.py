"""docs/gallery is current: every picture was drawn from its scenario as it is now, by the
renderer as it is now, and is the file the manifest recorded (nothing is drawn here;
docs/gallery/regenerate.py redraws and rewrites the manifest)."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from splinedeform.viz import RENDERER_VERSION

ROOT = Path(__file__).resolve().parents[1]
GALLERY = ROOT / "docs" / "gallery"
MANIFEST = json.loads((GALLERY / "manifest.json").read_text(encoding="utf-8"))
HOW = "run `python docs/gallery/regenerate.py {}` and commit the pictures and manifest.json"


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_every_example_and_every_picture_is_in_the_manifest():
    pictures = {p.name for p in GALLERY.glob("*.png")}
    expected = {f"{e.stem}.png" for e in (ROOT / "examples").glob("*.toml")} | \
        {"physics_compare.png"}
    assert pictures == expected, f"pictures and examples differ: {HOW.format('')}"
    assert set(MANIFEST["pictures"]) == expected, HOW.format("")


@pytest.mark.parametrize("name", sorted(MANIFEST["pictures"]))
def test_the_picture_is_current(name):
    entry = MANIFEST["pictures"][name]
    stem = name.removesuffix(".png")
    assert sha256(ROOT / entry["source"]) == entry["source_sha256"], \
        f"{entry['source']} changed since {name} was drawn: {HOW.format(stem)}"
    assert entry["renderer"] == RENDERER_VERSION, \
        f"{name} was drawn by renderer {entry['renderer']}, now {RENDERER_VERSION}: " \
        f"{HOW.format(stem)}"
    assert sha256(GALLERY / name) == entry["sha256"], \
        f"{name} was changed by hand: {HOW.format(stem)}"


def test_the_gallery_page_shows_every_picture():
    page = (ROOT / "docs" / "gallery.md").read_text(encoding="utf-8")
    for name in MANIFEST["pictures"]:
        assert f"(gallery/{name})" in page
    assert "last frame" not in page            # the pictures show the largest displacement
