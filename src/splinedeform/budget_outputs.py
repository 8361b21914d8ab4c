"""Resources of a run's outputs: files, CAD surfaces, probes and pictures, per frame.

:func:`output_terms` adds to an estimate (see :mod:`splinedeform.budget`) every output
format's memory, disk, files and work, each as a term naming the keys that drive it. With
``F`` frames, ``r`` = ``output.resolution``, a net of ``G = n_u n_v`` control points,
``P`` probes and ``n`` free coordinates (operation counts at about 1e9 per second):

frames
    ``3·10⁵`` operations each (energies, checks: the interpreter's cost of a frame);
sampled surfaces
    ``2 F r² (p + 1)² 3`` operations per sampled output (``vtu``, viewer, GIF, MP4) and
    once for the largest displacement;
files of numbers
    ``vtu`` ``2·10⁶ + 1.5·10³ r²`` operations per file; control nets ``1.5·10³`` (``json``)
    and ``300`` (``npz``) per number of ``F G 3``; meshes (``obj``, ``stl``, ``ply``)
    ``10⁴ r²`` each (welding and writing);
probes
    ``P (5·10⁴ + 6 F (p + 1)²)`` (one sparse evaluation matrix for all probes, its product
    with every frame's net, and the interpreter's cost of each probe's history); with
    ``images`` of the analytic solution another ``2 P min(600 n², 3·10⁹)`` for the densely
    sampled curves;
pictures (``images``)
    ``surfaces.png`` two 3-D panels of 48² samples, ``probes.png`` one panel of
    ``800 × 250`` pixels per probe (``3·10⁸`` each), ``modes.png`` one panel per mode:
    a 3-D panel of ``s²`` samples costs ``1.5·10⁸ + 1.5·10⁴ s²``; the probe picture's
    buffer ``800 · 250 P · 4`` bytes is held at once;
animations (GIF, MP4)
    one 3-D panel of ``r²`` samples per frame and format, plus ``10⁷`` to encode it; the
    frames are written as they are drawn, so memory holds at most 6 images of
    ``640 × 480`` (:func:`animation_memory`), not the film;
per-mode files of a modes solve
    the mode fields ``.vtu``, each mode's nets and each animated mode's film
    (:func:`mode_terms`);
viewer
    ``100`` operations per number written, ``(F r² + F G) 3`` numbers, and 1 MiB for the
    page and three.js;
CAD surfaces (``3dm``, ``step``, ``iges``), one NURBS surface per frame
    ``.3dm`` (openNURBS): ``10⁶ + 2·10⁴ G`` operations, ``1 KiB + 32 G`` bytes per frame,
    the file built in memory; STEP / IGES (OpenCASCADE): ``2·10⁷ + 10⁵ G`` operations,
    ``3 KiB + 120 G`` bytes per frame, and ``20 KiB + 1 KiB G`` of OpenCASCADE objects per
    frame held until the file is written.

The figures are upper-bound-minded orders of magnitude measured on a laptop core (the
.3dm, picture and probe costs) or stated from the writers' structure (STEP, IGES). On a
modes solve with its per-mode files (``benchmarks/bench_budget_modes.py``, one run under
load 10-12 on 2 cores), the work at 1e9 operations a second was 3.4 and 6.0 times the
processor time of runs animating 3 modes (9.7 s and 19.3 s estimated), and 0.95 times
that of a run without animations (0.07 s, the interpreter's fixed costs): an upper bound
within a factor 10 once the estimate is above a second. The wall clock on a busy machine
is longer, by the machine's load, not the run's.
"""

from __future__ import annotations

from typing import Any

#: operations of one 3-D panel of ``s²`` surface samples drawn by matplotlib
PANEL_WORK, PANEL_WORK_PER_SAMPLE = 1.5e8, 1.5e4
#: operations of one probe panel of probes.png, and its pixels (800 × 250)
PROBE_PANEL_WORK, PROBE_PANEL_PIXELS = 3e8, 800 * 250
#: operations to encode one animation frame
ENCODE_WORK = 1e7
#: bytes of one animation frame on disk, per format
ANIMATION_BYTES = {"gif": 65536.0, "mp4": 16384.0}
#: animation images (width, height) and how many an animation holds at once: the GIF's
#: palette samples (:data:`splinedeform.viz.animation.PALETTE_SAMPLES` and the peak frame);
#: the frames themselves are drawn and written one at a time
ANIMATION_PIXELS = (640, 480)
ANIMATION_HELD_FRAMES = 6
#: per CAD frame: (operations, operations per control point, bytes, bytes per control
#: point, bytes held in memory, bytes held per control point)
CAD_COSTS = {"3dm": (1e6, 2e4, 1024.0, 32.0, 1024.0, 64.0),
             "step": (2e7, 1e5, 3072.0, 120.0, 20480.0, 1024.0),
             "iges": (2e7, 1e5, 3072.0, 120.0, 20480.0, 1024.0)}


def panel_work(samples: int) -> float:
    """Operations of one shaded 3-D panel of ``s²`` samples: ``1.5·10⁸ + 1.5·10⁴ s²``."""
    return PANEL_WORK + PANEL_WORK_PER_SAMPLE * samples ** 2


def output_terms(scenario: Any, model: Any, frames: int, frames_key: str
                 ) -> dict[str, list[Any]]:
    """Terms of ``memory`` (stages held one at a time), ``disk``, ``files`` and ``work`` of
    every output of ``scenario`` over ``frames`` frames (see the module docstring)."""
    from .budget import Term, net_size

    output, solve = scenario.output, scenario.solve
    formats = set(output.formats)
    F, r = frames, output.resolution
    r2 = r ** 2
    n_u, n_v, p = net_size(model)
    G, n = n_u * n_v, model.n_free
    res, fmt, probes_key = "output.resolution", "output.formats", "output.probes"
    P = max(len(output.probes), 1)          # the centre of the domain when none is given
    memory: list[Term] = [Term(F * r2 * 24.0 * 2, f"{F} frames x {r}² surface samples x "
                                                  "48 bytes", (frames_key, res))]
    disk: list[Term] = []
    files: list[Term] = []
    sampled = [f for f in ("vtu", "viewer", "gif", "mp4") if f in formats]
    work = [Term(3e5 * F, f"{F} frames (energies and checks)", (frames_key,)),
            Term(2.0 * F * r2 * (p + 1) ** 2 * 3 * (1 + len(sampled)),
                 f"{F} frames x {r}² samples, {1 + len(sampled)} time(s)", (frames_key, res)),
            Term(P * (5e4 + 6.0 * F * (p + 1) ** 2), f"{P} probe(s) over {F} frames",
                 (probes_key, frames_key))]

    if "vtu" in formats:
        disk.append(Term(F * r2 * 104.0, f"{F} .vtu files of {r}² points",
                         (frames_key, res, fmt)))
        files.append(Term(F + 1.0, f"{F} .vtu files and a .pvd", (frames_key, fmt)))
        work.append(Term(F * (2e6 + 1.5e3 * r2), f"writing {F} .vtu files of {r}² points",
                         (frames_key, res, fmt)))
    for ext, size, ops in (("json", 25.0, 1.5e3), ("npz", 8.0, 300.0)):
        if ext in formats:
            disk.append(Term(F * G * 3 * size, f"control nets .{ext}", (frames_key, fmt)))
            work.append(Term(F * G * 3 * ops, f"writing control nets .{ext}",
                             (frames_key, fmt)))
    if "viewer" in formats:
        numbers = (F * r2 + F * G) * 3.0
        disk.append(Term(numbers * 4 * 4 / 3 + 2**20, "viewer.html", (frames_key, res, fmt)))
        work.append(Term(100.0 * numbers, f"viewer.html: {numbers:.3g} numbers written",
                         (frames_key, res, fmt)))
    for ext in ("obj", "stl", "ply"):
        if ext in formats:
            disk.append(Term(r2 * 100.0, f".{ext} mesh", (res, fmt)))
            work.append(Term(r2 * 1e4, f".{ext} mesh of {r}² points", (res, fmt)))

    for ext, (ops, ops_g, size, size_g, held, held_g) in CAD_COSTS.items():
        if ext in formats:
            surfaces = F + 1.0                # the initial surface and every frame
            what = f"{surfaces:.0f} NURBS surfaces of {n_u} x {n_v} control points in .{ext}"
            work.append(Term(surfaces * (ops + ops_g * G), what, (frames_key, fmt)))
            disk.append(Term(surfaces * (size + size_g * G), what, (frames_key, fmt)))
            memory.append(Term(surfaces * (held + held_g * G), what, (frames_key, fmt)))

    animated = [f for f in ("gif", "mp4") if f in formats]
    if animated:
        memory.append(Term(animation_memory(F), f"animation images of 640 x 480 (at most "
                           f"{min(F, ANIMATION_HELD_FRAMES)} held)", (frames_key, fmt)))
        work.append(Term(F * len(animated) * (panel_work(r) + ENCODE_WORK),
                         f"rendering {F} animation frames of {r}² samples "
                         f"({', '.join(animated)})", (frames_key, res, fmt)))
    for ext, size in ANIMATION_BYTES.items():
        if ext in formats:
            disk.append(Term(F * size, f"{F} {ext} frames", (frames_key, fmt)))

    if "images" in formats:
        modes = min(solve.modes, n) if solve.kind != "static" else 0
        work.append(Term(2 * panel_work(48) + modes * panel_work(40),
                         f"pictures: surfaces.png, modes.png ({modes} modes)",
                         ("solve.modes", fmt)))
        disk.append(Term((2 + modes) * 2.0**19, "pictures", (fmt,)))
        if solve.kind == "dynamic":
            work.append(Term(P * PROBE_PANEL_WORK, f"probes.png: {P} panel(s)",
                             (probes_key, fmt)))
            memory.append(Term(P * PROBE_PANEL_PIXELS * 4.0 * 2,
                               f"probes.png: {P} panels of 800 x 250 pixels",
                               (probes_key, fmt)))
            disk.append(Term(P * PROBE_PANEL_PIXELS * 0.5, "probes.png", (probes_key, fmt)))
            if solve.method == "analytic":
                work.append(Term(2.0 * P * min(600.0 * n * n, 3e9),
                                 f"{P} densely sampled probe curve(s)", (probes_key, fmt)))
    if "report" in formats:
        disk.append(Term(P * F * 3 * 25.0 + 65536.0, "report.json and report.md",
                         (probes_key, frames_key, fmt)))
        work.append(Term(P * F * 3 * 200.0, f"report of {P} probe(s) over {F} frames",
                         (probes_key, frames_key, fmt)))
    others = sum(1 for f in formats if f not in ("vtu", "images", "report")) \
        + 3 * ("images" in formats) + 2 * ("report" in formats)
    if others:
        files.append(Term(float(others), "one file per other format", (fmt,)))
    terms = {"memory": memory, "disk": disk, "files": files, "work": work}
    if solve.kind == "modes":
        for resource, more in mode_terms(scenario, model, F, frames_key).items():
            terms[resource] += more
    return terms


def animation_memory(frames: int) -> float:
    """Bytes an animation holds at once: :data:`ANIMATION_HELD_FRAMES` images of
    ``640 × 480 × 3`` (the palette's sample frames), twice (their stack for the median
    cut), the figure's RGBA canvas and its background, and the GIF's colour lookup table
    of ``2²⁴`` 16-bit entries, and 8 MiB for matplotlib's figure and renderer:
    ``2 min(F, 6) 640·480·3 + 2 · 640·480·4 + 2²⁵ + 2²³``."""
    width, height = ANIMATION_PIXELS
    return (2.0 * min(frames, ANIMATION_HELD_FRAMES) * width * height * 3
            + 2.0 * width * height * 4 + 2.0**25 + 2.0**23)


def mode_terms(scenario: Any, model: Any, frames: int, frames_key: str
               ) -> dict[str, list[Any]]:
    """Terms of the per-mode files of a modes solve of ``K`` modes (``solve.modes``),
    ``A`` of them animated besides mode 1 (``output.animate_modes``), ``F`` frames:

    ``<name>_modes.vtu`` (vtu)
        ``K + 1`` nets sampled at ``r²`` points (``2 (K + 1) r² (p + 1)² 3`` operations),
        written as ``2·10⁶ + 1.5·10³ r² (K + 1)`` operations and ``r² (104 + 32 K)``
        bytes; ``(K + 1) r² 48`` bytes of samples held;
    ``<name>_mode<k>_nets.json/.npz``
        ``K`` files of ``F G 3`` numbers each (as the frames' nets), and the nets of one
        mode over its frames held, ``F G 24`` bytes;
    ``<name>_mode<k>.gif/.mp4``
        ``A`` animations per format, each as the run's own animation: ``F`` frames
        sampled and rendered, ``F (1.5·10⁸ + 1.5·10⁴ r² + 10⁷)`` operations;
    ``<name>_mode<k>.pvd`` + ``<name>_mode<k>_0000.vtu`` … (vtu)
        ``A`` series, each as the run's own: ``F + 1`` files, ``F r² 104`` bytes and
        ``F (2·10⁶ + 1.5·10³ r²)`` operations.
    """
    from .budget import Term, net_size

    output = scenario.output
    formats = set(output.formats)
    F, r = frames, output.resolution
    r2 = r ** 2
    n_u, n_v, p = net_size(model)
    G = n_u * n_v
    K = min(scenario.solve.modes, model.n_free)
    res, fmt, modes_key = "output.resolution", "output.formats", "solve.modes"
    memory: list[Term] = []
    disk: list[Term] = []
    files: list[Term] = []
    work: list[Term] = []
    if "vtu" in formats:
        what = f"mode fields .vtu: {K} modes at {r}² points"
        work.append(Term(2.0 * (K + 1) * r2 * (p + 1) ** 2 * 3 + 2e6 + 1.5e3 * r2 * (K + 1),
                         what, (modes_key, res, fmt)))
        disk.append(Term(r2 * (104.0 + 32.0 * K), what, (modes_key, res, fmt)))
        memory.append(Term((K + 1) * r2 * 48.0, what, (modes_key, res, fmt)))
        files.append(Term(1.0, "mode fields .vtu", (fmt,)))
    for ext, size, ops in (("json", 25.0, 1.5e3), ("npz", 8.0, 300.0)):
        if ext in formats:
            what = f"{K} mode nets .{ext} of {F} frames"
            disk.append(Term(K * F * G * 3 * size, what, (modes_key, frames_key, fmt)))
            work.append(Term(K * F * G * 3 * ops, what, (modes_key, frames_key, fmt)))
            files.append(Term(float(K), what, (modes_key, fmt)))
    animated = [ext for ext in ("gif", "mp4") if ext in formats]
    A = sum(1 for k in output.animate_modes or (1,) if k != 1)
    if animated and A:
        what = f"{A} mode animation(s) of {F} frames ({', '.join(animated)})"
        keys = ("output.animate_modes", frames_key, res, fmt)
        per = F * (panel_work(r) + ENCODE_WORK + 2.0 * r2 * (p + 1) ** 2 * 3)
        work.append(Term(A * len(animated) * per, what, keys))
        disk.append(Term(A * F * sum(ANIMATION_BYTES[e] for e in animated), what, keys))
        files.append(Term(float(A * len(animated)), what, keys))
        memory.append(Term(animation_memory(F) + F * r2 * 48.0, what, keys))
    if "vtu" in formats and A:
        what = f"{A} mode series of {F} .vtu files of {r}² points"
        keys = ("output.animate_modes", frames_key, res, fmt)
        disk.append(Term(A * F * r2 * 104.0, what, keys))
        files.append(Term(A * (F + 1.0), what, keys))
        work.append(Term(A * F * (2e6 + 1.5e3 * r2), what, keys))
    if (animated and A) or any(e in formats for e in ("json", "npz")):
        memory.append(Term(F * G * 24.0, f"the nets of one mode over {F} frames",
                           (frames_key, fmt)))
    return {"memory": memory, "disk": disk, "files": files, "work": work}
