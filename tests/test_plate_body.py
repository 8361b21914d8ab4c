"""The plate of a body is assembled in ``physics/`` (:mod:`splinedeform.physics.plate_body`),
as the shell's body is (:mod:`splinedeform.physics.shell_body`); :class:`BodyModel` is a
constructor of the one model on that system and assembles nothing itself."""

from __future__ import annotations

import inspect
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import splinedeform as sd
import splinedeform.body.model
from splinedeform.assembly import patch_matrices
from splinedeform.body import Body
from splinedeform.physics import plate_body

from body_patches import flat_patch
import test_formulation

PLATE = sd.Material(w10=1.0, w01=1.0, w20=1.0, w11=1.0, w02=1.0)


def halves() -> Body:
    """The unit square in two patches of different spans (a non-conforming interface, so
    the system has a displacement and a rotation penalty)."""
    return Body([flat_patch((0, 0.5), (0, 1), (3, 6)), flat_patch((0.5, 1), (0, 1), (2, 4))])


def test_the_plate_body_formulation_imports_no_model():
    test_formulation.test_no_formulation_imports_a_model(Path(plate_body.__file__))


def test_the_body_model_is_the_system_of_physics():
    """The model's reduced matrices are those of :func:`plate_body.body_system` (one
    assembly: equal to its round-off), and the body's stiffness is the patches' own plus
    the couplings: ``K − diag(K_p)`` is what :func:`plate_body.couplings` adds."""
    body = halves()
    system = plate_body.body_system(body, PLATE, "clamped")
    model = sd.BodyModel(body, PLATE, boundary="clamped")
    M, _, K = model.matrices()
    scale = abs(system.reduced[0]).max()
    assert abs(K - system.reduced[0]).max() <= 1e-14 * scale
    assert abs(M - system.reduced[1]).max() <= 1e-14 * abs(M).max()
    own = [patch_matrices(s, PLATE, "intrinsic", False)[2] for s in body.patches]
    coupling = system.full[0] - sp.block_diag(own)
    added = sum(plate_body.couplings(body.patches, body.topology, body.trim_interfaces,
                                     PLATE, system.constraints))
    # the penalties of 1e5 × the plate's weights: their sum to round-off of their size
    assert abs(coupling - added).max() <= 1e-12 * abs(added).max()
    assert abs(added).max() > 0


def test_the_body_model_constructor_assembles_nothing():
    source = inspect.getsource(splinedeform.body.model.BodyModel.__init__)
    for word in ("block_diag", "patch_matrices", "interface_coupling", "c0_coupling",
                 "curve_penalty", "build_body_constraints"):
        assert word not in source
    assert np.isclose(sd.BodyModel(halves(), PLATE, "clamped").n_free,
                      plate_body.body_system(halves(), PLATE, "clamped").constraints.n_free,
                      rtol=0, atol=0.5)          # integers, compared to half a unit
