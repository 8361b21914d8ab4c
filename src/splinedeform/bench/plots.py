"""Log–log plot of time against free control points (regime a), fitted slopes in the legend."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from ..export import write_with
from .bookkeeping import Row, fitted_slope
from .tables import NAMES


def plot(rows: list[Row], family: str, path: Path, methods: Sequence[str]) -> Path:
    """Measured runs solid, extrapolated or forecast ones hollow and dotted, △ lower bounds."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fam = [r for r in rows if r.family == family and r.regime == "size"]
    fig, ax = plt.subplots(figsize=(7, 5))
    series = [("analytic", "seconds", NAMES["analytic"], "k", "o"),
              ("analytic-all", "seconds", NAMES["analytic-all"], "0.45", "s")]
    series += [(m, "seconds", NAMES.get(m, m), None, "o") for m in methods]
    for solver, key, label, colour, marker in series:
        sr = [r for r in fam if r.solver == solver]
        ok = [r for r in sr if r.status in ("ok", "exact")]
        est = [r for r in sr if r.status in ("over budget", "skipped", "not run")]
        slope = fitted_slope(sr, key)
        text = label + (f" (p = {slope:.2f})" if math.isfinite(slope) else "")
        line, = ax.loglog([r.n_free for r in ok], [getattr(r, key) for r in ok], marker=marker,
                          color=colour, label=text)
        if est:
            ax.loglog([r.n_free for r in est], [r.estimate for r in est], marker=marker,
                      linestyle=":", mfc="none", color=line.get_color())
            lower = [r for r in est if r.status == "over budget" and not math.isfinite(r.estimate)]
            ax.loglog([r.n_free for r in lower], [r.seconds for r in lower], marker="^",
                      linestyle="none", mfc="none", color=line.get_color())
    ax.set_xlabel("free control points per coordinate")
    ax.set_ylabel("time [s]")
    ax.set_title(f"{family}: cost against net size (hollow: extrapolated or forecast; "
                 "△: lower bound)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    write_with(path, lambda tmp: fig.savefig(tmp, format="png", dpi=110))
    plt.close(fig)
    return path
