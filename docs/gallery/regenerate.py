"""Regenerate docs/gallery.md and its pictures from the scenario files in examples/.

Each example is run with the command line (``splinedeform run FILE -o TMP --quiet``); its
picture of the initial and final surface (``modes.png`` for a modes solve) is reduced to a
dithered palette PNG under 150 kB and the page lists, per example, its title, the comment at the
top of its file and the command that reproduces it.

Usage: ``python docs/gallery/regenerate.py`` from the repository root.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
GALLERY = ROOT / "docs" / "gallery"
PAGE = ROOT / "docs" / "gallery.md"
MAX_BYTES = 150_000
WIDTH = 780


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


def render(example: Path, workdir: Path) -> tuple[str, Path]:
    """Run one example; return its title and the picture to show."""
    scenario = tomllib.loads(example.read_text(encoding="utf-8"))
    out = workdir / example.stem
    subprocess.run([sys.executable, "-m", "splinedeform.cli", "run", str(example), "-o", str(out),
                    "--quiet"], check=True)
    kind = scenario.get("solve", {}).get("kind", "static")
    picture = out / ("modes.png" if kind == "modes" else "surfaces.png")
    return scenario.get("title", example.stem), picture


def main() -> None:
    GALLERY.mkdir(parents=True, exist_ok=True)
    page = ["# Gallery", "",
            "One picture per scenario in `examples/`: the initial surface and the last frame,",
            "coloured by the displacement magnitude (a modes solve shows its lowest mode",
            "shapes). Each is what `splinedeform run` writes as `surfaces.png` / `modes.png`;",
            "regenerate them all with `python docs/gallery/regenerate.py`.", ""]
    with tempfile.TemporaryDirectory() as tmp:
        for example in sorted(EXAMPLES.glob("*.toml")):
            title, picture = render(example, Path(tmp))
            target = GALLERY / f"{example.stem}.png"
            shrink(picture, target)
            page += [f"## {title}", "", f"![{title}](gallery/{target.name})", "",
                     *description(example), "",
                     f"`splinedeform run examples/{example.name} -o out/{example.stem}`", ""]
            print(f"{target.relative_to(ROOT)}: {target.stat().st_size} bytes")
    sys.path.insert(0, str(GALLERY))
    import physics_figure

    shrink(physics_figure.main(), GALLERY / "physics_compare.png")
    page += physics_figure.TEXT
    PAGE.write_text("\n".join(page).rstrip() + "\n", encoding="utf-8")
    shutil.rmtree(GALLERY / "__pycache__", ignore_errors=True)


if __name__ == "__main__":
    main()
