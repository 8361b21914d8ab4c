"""Regenerate docs/gallery.md, its pictures and their manifest from the scenario files in examples/.

Each example is run with its own settings but only the ``images`` output (the library's
:func:`splinedeform.pipeline.run`, as ``splinedeform run`` does); its ``surfaces.png``
(initial surface and the frame of largest displacement; ``modes.png`` for a modes solve)
is reduced to a dithered palette PNG under 150 kB. The page lists, per example, its
title, the comment at the top of its file and the command that reproduces it.

``docs/gallery/manifest.json`` records, for every picture, the SHA-256 of the file it was
made from (the scenario, or ``physics_figure.py``), of the picture itself, and the
renderer version (:data:`splinedeform.viz.RENDERER_VERSION`); ``tests/test_gallery.py``
compares them with the files as they are, without drawing anything.

Usage: ``python docs/gallery/regenerate.py [NAME ...]`` from the repository root (names
are example stems; none: every example and the physics figure).
"""

from __future__ import annotations

import hashlib
import json
import shutil
import sys
import tempfile
import time
import tomllib
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
GALLERY = ROOT / "docs" / "gallery"
PAGE = ROOT / "docs" / "gallery.md"
MANIFEST = GALLERY / "manifest.json"
MAX_BYTES = 150_000
WIDTH = 780
INTRO = ["# Gallery", "",
         "One picture per scenario in `examples/`: the initial surface and the frame of largest",
         "displacement, coloured by the displacement magnitude (a modes solve shows its lowest",
         "mode shapes). Each is what `splinedeform run` writes as `surfaces.png` / `modes.png`;",
         "regenerate them with `python docs/gallery/regenerate.py` (the test suite checks, from",
         "`gallery/manifest.json`, that every picture is current with its scenario and the",
         "renderer).", ""]


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def description(path: Path) -> list[str]:
    """The comment block at the top of a scenario file, as paragraphs of markdown."""
    lines = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        lines.append(line[1:].strip())
    return lines


def shrink(source: Path, target: Path) -> None:
    """Resize to ``WIDTH`` px and store with a dithered palette, under MAX_BYTES."""
    image = Image.open(source).convert("RGB")
    if image.width > WIDTH:
        image = image.resize((WIDTH, round(image.height * WIDTH / image.width)), Image.LANCZOS)
    for colours in (256, 128, 64):
        image.quantize(colors=colours, method=Image.Quantize.FASTOCTREE,
                       dither=Image.Dither.FLOYDSTEINBERG).save(target, optimize=True)
        if target.stat().st_size < MAX_BYTES:
            return
    raise RuntimeError(f"{target} stays above {MAX_BYTES} bytes")


def render(example: Path, workdir: Path) -> Path:
    """Run one example with the ``images`` output only; return the picture to show."""
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario, with_overrides

    scenario = with_overrides(load_scenario(example), {"output.formats": ["images"]})
    out = workdir / example.stem
    run(scenario, out)
    return out / ("modes.png" if scenario.solve.kind == "modes" else "surfaces.png")


def title_of(example: Path) -> str:
    return str(tomllib.loads(example.read_text(encoding="utf-8")).get("title", example.stem))


def page_text(examples: list[Path]) -> str:
    import physics_figure

    page = list(INTRO)
    for example in examples:
        title = title_of(example)
        page += [f"## {title}", "", f"![{title}](gallery/{example.stem}.png)", "",
                 *description(example), "",
                 f"`splinedeform run examples/{example.name} -o out/{example.stem}`", ""]
    page += physics_figure.TEXT
    return "\n".join(page).rstrip() + "\n"


def entry(picture: Path, source: Path, renderer: int) -> dict[str, object]:
    return {"source": source.relative_to(ROOT).as_posix(), "source_sha256": sha256(source),
            "renderer": renderer, "sha256": sha256(picture)}


def main(names: list[str]) -> None:
    from splinedeform.viz import RENDERER_VERSION

    sys.path.insert(0, str(GALLERY))
    import physics_figure

    GALLERY.mkdir(parents=True, exist_ok=True)
    examples = sorted(EXAMPLES.glob("*.toml"))
    unknown = set(names) - {e.stem for e in examples} - {"physics_compare"}
    if unknown:
        raise SystemExit(f"no example named {sorted(unknown)}")
    chosen = [e for e in examples if not names or e.stem in names]
    manifest = json.loads(MANIFEST.read_text()) if MANIFEST.exists() else {"pictures": {}}
    pictures = manifest["pictures"]
    with tempfile.TemporaryDirectory() as tmp:
        for example in chosen:
            start = time.perf_counter()
            target = GALLERY / f"{example.stem}.png"
            shrink(render(example, Path(tmp)), target)
            pictures[target.name] = entry(target, example, RENDERER_VERSION)
            print(f"{target.relative_to(ROOT)}: {target.stat().st_size} bytes, "
                  f"{time.perf_counter() - start:.1f} s", flush=True)
    if not names or "physics_compare" in names:
        target = GALLERY / "physics_compare.png"
        shrink(physics_figure.main(), target)
        pictures[target.name] = entry(target, GALLERY / "physics_figure.py", RENDERER_VERSION)
    manifest = {"format": "splinedeform-gallery", "version": 1,
                "pictures": dict(sorted(pictures.items()))}
    MANIFEST.write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    PAGE.write_text(page_text(examples), encoding="utf-8")
    shutil.rmtree(GALLERY / "__pycache__", ignore_errors=True)


if __name__ == "__main__":
    main(sys.argv[1:])
