"""The regimes and goals of the cost study now live in :mod:`splinedeform.bench`
(:mod:`~splinedeform.bench.regimes`, :mod:`~splinedeform.bench.goals`); this name is kept
for the command line and older scripts.
"""

from __future__ import annotations

from .bench.goals import Goal, issue_goals
from .bench.regimes import run
from .bench.timing import blas_threads

__all__ = ["Goal", "blas_threads", "issue_goals", "run"]
